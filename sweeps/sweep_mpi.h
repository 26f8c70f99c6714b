#pragma once
// A sweep on MPI ranks (`mpirun -n N needle sweep FILE --out DIR`): rank 0 hands out the cases not done, one at a
// time to whichever rank asks, writes each case's record as it comes back and builds the table; ranks 1..N-1 run
// the cases (so N ranks give N - 1 workers; rank 0 waits without using a core). With one rank, rank 0 runs them.
// The case folders are written where the worker runs: DIR should be on a file system every node sees.
// Built when CMake finds MPI (Debian's OpenMPI); otherwise mpi_available() is false and a launch under mpirun is refused.
#include <filesystem>

#include "sweeps/sweep_executor.h"
#include "sweeps/sweep_plan.h"

namespace needle {

bool mpi_available();
// Whether this process was started by mpirun/srun with MPI (OpenMPI's or PMIx's environment).
bool launched_by_mpi();

// MPI_Init on construction, MPI_Finalize on destruction.
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  int rank_ = 0, size_ = 1;
};

// Runs the cases not done in dir across the session's ranks: rank 0 returns once every case has come back (then it
// writes the table); the other ranks return when rank 0 has no more work for them.
void run_sweep_on_mpi(const MpiSession& mpi, const SweepPlan& plan, const std::filesystem::path& dir, int threads_per_case, bool quiet);

}  // namespace needle
