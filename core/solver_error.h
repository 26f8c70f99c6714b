#pragma once
// A run that cannot go on (blow-up, inverted particle, collapsed time step, runaway penetration):
// the solver stops with this reason instead of writing NaN. Distinct from InputError (bad input).
#include <stdexcept>

namespace needle {

struct SolverError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace needle

namespace needle {

// A study (a sweep) whose table is written but whose cases did not all finish: some stopped, timed out, failed or
// were not run. The command exits 3, as a run the solver stopped does, so that a script can tell.
struct StudyIncomplete : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The exit status of a command this one ran for the user (mpirun, for `needle sweep --mpi`), which has said why
// already: main returns it without a line of its own.
struct PassedExitStatus {
  int code;
};

}  // namespace needle
