#pragma once
// Who runs a sweep's cases: worker processes on this machine (`--jobs N`: this program started again, one process
// a case, `needle sweep FILE --out DIR --task-index I`), one case of a batch array (`--task-index I`, or Slurm's
// SLURM_ARRAY_TASK_ID), or MPI ranks (sweep_mpi.h). Each case is written by the case itself (cases/<name>/case.json),
// so every way of running gives the same table, and a sweep started again runs only the cases not done.
#include <filesystem>
#include <functional>
#include <string>

#include "sweeps/design_case.h"
#include "sweeps/sweep_plan.h"

namespace needle {

struct SweepWorkers {
  std::string sweep_file;     // handed to the worker processes
  int jobs = 1;               // worker processes at once
  int threads_per_case = 1;   // each case's worker threads (a run's results do not depend on it)
  bool quiet = false;         // no progress lines
  bool allow_other_code = false;  // handed to the workers (--allow-other-code; sweep_plan.h)
  double case_time_limit_s = 0;  // a case running longer is stopped (SIGTERM, SIGKILL 10 s later) and recorded timed_out; 0: none
};

// Progress of a sweep on stderr: each case as it ends, with the counts and an estimate of the time left.
class SweepProgress {
 public:
  SweepProgress(int total_cases, int done_before, int workers, bool quiet);
  void case_done(const CaseResult& result, double wall_s);
  void case_started(const std::string& name, const std::string& values);

 private:
  int total_, done_, failed_ = 0, workers_, started_here_ = 0, done_here_ = 0;
  double start_s_, case_seconds_ = 0;
  bool quiet_;
};

// Runs the plan's cases that are not done, `jobs` worker processes at a time. A worker that dies without a record
// is recorded as failed with its exit status; the sweep goes on. Ctrl-C or SIGTERM: the workers stop, what is done
// stays done, and Interrupted is thrown.
void run_sweep_with_workers(const SweepPlan& plan, const std::filesystem::path& dir, const SweepWorkers& workers);

// The cases of the plan not done yet in dir.
std::vector<SweepCase> cases_to_run(const SweepPlan& plan, const std::filesystem::path& dir);

// In a worker process this sweep started (the environment names the parent's pid): the kernel sends it SIGTERM when
// its parent dies, even by SIGKILL, so that no orphan goes on running a case the next run of the sweep starts again;
// a worker whose parent is gone already stops at once (Interrupted). Nothing outside a sweep's worker.
void die_with_sweep_parent();

// The case index a batch array hands this process: the environment's SLURM_ARRAY_TASK_ID, or -1 when not set.
int batch_array_task_index();

}  // namespace needle
