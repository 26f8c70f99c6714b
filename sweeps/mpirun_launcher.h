#pragma once
// `needle sweep FILE --out DIR --mpi N`: the MPI sweep (sweep_mpi.h) started by needle itself, so that an interruption
// ends it with exit 130 as the other ways of running a sweep do. Run as `mpirun -n N needle sweep ...`, Ctrl-C reaches
// mpirun, and OpenMPI's mpirun then exits 1 whatever its ranks return (measured with OpenMPI 4.1; it also refuses to
// forward SIGINT to the ranks). Here needle starts `mpirun -n N --bind-to none --stdin none` (with --oversubscribe
// where N is more than the cores, --allow-run-as-root as root) on the same sweep in a process group of its own, so
// that the terminal's Ctrl-C reaches needle alone; needle then stops the job (SIGTERM to mpirun, which aborts its
// ranks: the finished cases stay), waits for it and reports the interruption. mpirun dies with needle (a parent-death
// signal), so a needle killed outright leaves no job behind.
#include <filesystem>
#include <string>
#include <vector>

namespace needle {

// Runs `mpirun ... <this needle> <sweep_args>` and returns its exit status (rank 0's when it exits non-zero). Throws
// Interrupted (after the job has ended) on SIGINT or SIGTERM; InputError when no mpirun is on the PATH or ranks < 1.
int run_sweep_under_mpirun(const std::vector<std::string>& sweep_args, int ranks, const std::filesystem::path& out_dir);

}  // namespace needle
