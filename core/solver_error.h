#pragma once
// A run that cannot go on (blow-up, inverted particle, collapsed time step, runaway penetration):
// the solver stops with this reason instead of writing NaN. Distinct from InputError (bad input).
#include <stdexcept>

namespace needle {

struct SolverError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace needle
