// `needle sweep FILE --out DIR`: a design sweep (docs/sweeps.md): every case the whole pipeline in its own run folder,
// on worker processes (--jobs), MPI ranks (under mpirun) or one case of a batch array (--task-index, Slurm's
// SLURM_ARRAY_TASK_ID), and the table of all cases (--collect builds it from what the cases wrote).
#include "apps/sweep_command.h"

#include <fmt/format.h>
#include <memory>

#include "apps/cli_checks.h"
#include "core/input_error.h"
#include "core/parallel.h"
#include "core/solver_error.h"
#include "sweeps/mpirun_launcher.h"
#include "sweeps/sweep_executor.h"
#include "sweeps/sweep_mpi.h"
#include "sweeps/sweep_plan.h"
#include "sweeps/sweep_table.h"
#include "runs/writer_lock.h"

#ifndef NEEDLE_DATA_DIR
#define NEEDLE_DATA_DIR "data"
#endif

namespace needle {
namespace fs = std::filesystem;
namespace {

struct SweepOptions {
  std::string file, out_dir;
  int jobs = 1, threads = 0, task_index = -1, mpi_ranks = 0;
  bool collect = false, count = false, quiet = false, allow_other_code = false;
};

SweepCounts print_table_summary(const fs::path& dir, const SweepPlan& plan, const std::vector<CaseResult>& rows) {
  const SweepCounts c = count_cases(rows);
  fmt::print("sweep: {} cases: {} finished, {} stopped, {} infeasible, {} timed out, {} failed, {} not run yet\n", rows.size(), c.finished, c.stopped,
             c.infeasible, c.timed_out, c.failed, c.pending);
  for (const DeflectionZero& z : deflection_zeros(plan.variables, rows))
    fmt::print("sweep: the deflection crosses zero at {} = {:.4g}{}\n", z.variable, z.value, z.others.empty() ? "" : " (" + describe_values(z.others) + ")");
  fmt::print("sweep: table {} and {}\n", (dir / "sweep.csv").string(), (dir / "sweep.json").string());
  return c;
}

// Writes the table, then says whether every case finished: StudyIncomplete (exit 3) when some stopped, timed out,
// failed or were not run. A tip that cannot be ground (infeasible) is the design's answer, not a case that failed.
void write_and_print_table(const fs::path& dir, const SweepPlan& plan) {
  const std::vector<CaseResult> rows = collect_case_records(dir, plan.cases);
  write_sweep_table(dir, plan, rows, std::string(NEEDLE_DATA_DIR) + "/paper/reference.json");
  const SweepCounts c = print_table_summary(dir, plan, rows);
  const int unfinished = c.stopped + c.timed_out + c.failed + c.pending;
  if (unfinished > 0)
    throw StudyIncomplete(fmt::format("{} of {} cases did not finish ({} stopped, {} timed out, {} failed, {} not run): the table holds the others; "
                                      "exit 3",
                                      unfinished, rows.size(), c.stopped, c.timed_out, c.failed, c.pending));
}

void run(const SweepOptions& o) {
  const SweepPlan plan = read_sweep_file(o.file);
  if (o.count) {
    fmt::print("{}\n", plan.cases.size());
    return;
  }
  NEEDLE_REQUIRE(!o.out_dir.empty(), "--out: give the sweep's folder");
  NEEDLE_REQUIRE(o.jobs >= 1 && o.jobs <= 256, fmt::format("--jobs must be from 1 to 256 (got {})", o.jobs));
  const fs::path dir(o.out_dir);
  if (o.mpi_ranks > 0) {  // this same sweep under mpirun, started here so that Ctrl-C exits 130 (mpirun_launcher.h)
    NEEDLE_REQUIRE(!o.collect && o.task_index < 0 && o.jobs == 1, "--mpi runs the whole sweep on MPI ranks: give it without --jobs, --task-index or --collect");
    NEEDLE_REQUIRE(!launched_by_mpi(), "--mpi starts mpirun itself: run `needle sweep --mpi N` without mpirun");
    NEEDLE_REQUIRE(mpi_available(), "--mpi: this needle was built without MPI (install libopenmpi-dev and build again)");
    std::vector<std::string> args = {"sweep", fs::absolute(o.file).string(), "--out", fs::absolute(dir).string()};
    if (o.threads > 0) args.insert(args.end(), {"--threads", std::to_string(o.threads)});
    if (o.quiet) args.emplace_back("--quiet");
    if (o.allow_other_code) args.emplace_back("--allow-other-code");
    const int status = run_sweep_under_mpirun(args, o.mpi_ranks, dir);
    if (status != 0) throw PassedExitStatus{status};
    return;
  }
  const nlohmann::json stored_plan = sweep_plan_to_json(plan);
  if (o.collect) {
    NEEDLE_REQUIRE(fs::exists(dir / "sweep_plan.json"), fmt::format("--collect: {} holds no sweep (no sweep_plan.json)", dir.string()));
    const auto lock = lock_output_folder(dir);
    claim_study_folder(dir, "sweep_plan.json", stored_plan, o.allow_other_code);
    write_and_print_table(dir, plan);
    return;
  }
  const int task = o.task_index >= 0 ? o.task_index : batch_array_task_index();
  if (task >= 0) {  // one case: a worker process, or a batch array's task
    die_with_sweep_parent();
    NEEDLE_REQUIRE(task < static_cast<int>(plan.cases.size()),
                   fmt::format("--task-index {}: the sweep has cases 0 to {}", task, plan.cases.size() - 1));
    claim_study_folder(dir, "sweep_plan.json", stored_plan, o.allow_other_code);
    const SweepCase& c = plan.cases[static_cast<size_t>(task)];
    if (read_done_case(dir, c.name, c.values)) {
      fmt::print("sweep: {} was done before\n", c.name);
      return;
    }
    const int threads = o.threads > 0 ? o.threads : hardware_threads();
    const CaseResult r = run_design_case(plan.base, c.index, c.name, c.values, dir, threads, o.quiet, c.label);
    fmt::print("sweep: {} {} ({}){}\n", r.name, r.status, describe_values(r.values),
               ": " + (r.status == "finished" ? finished_case_words(r) : r.reason));
    return;
  }
  if (launched_by_mpi()) {
    MpiSession mpi;
    const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
    const int local_ranks = local ? std::max(1, std::atoi(local)) : 1;
    const int threads = o.threads > 0 ? o.threads : std::max(1, hardware_threads() / std::max(1, local_ranks - 1));
    std::unique_ptr<WriterLock> lock;  // held by the rank that writes the table; the others run cases only
    if (mpi.rank() == 0) {
      lock = lock_output_folder(dir);
      const auto infeasible = check_sweep_cases(plan);
      claim_study_folder(dir, "sweep_plan.json", stored_plan, o.allow_other_code);
      if (!o.quiet)
        fmt::print(stderr, "sweep: {} cases ({} with tips that cannot be ground) on {} MPI ranks: {} worker(s), {} thread(s) a case\n", plan.cases.size(),
                   infeasible.size(), mpi.size(), std::max(1, mpi.size() - 1), threads);
    }
    run_sweep_on_mpi(mpi, plan, dir, threads, o.quiet);
    if (mpi.rank() == 0) write_and_print_table(dir, plan);
    return;
  }
  // The parent holds the folder while its workers run one case each (a worker, like a batch array's task, takes no folder
  // lock: its case's run folder has its own).
  const auto lock = lock_output_folder(dir);
  const auto infeasible = check_sweep_cases(plan);
  claim_study_folder(dir, "sweep_plan.json", stored_plan, o.allow_other_code);
  SweepWorkers workers;
  workers.sweep_file = fs::absolute(o.file).string();
  workers.jobs = o.jobs;
  workers.threads_per_case = o.threads > 0 ? o.threads : std::max(1, hardware_threads() / o.jobs);
  workers.quiet = o.quiet;
  workers.allow_other_code = o.allow_other_code;
  if (!o.quiet)
    fmt::print(stderr, "sweep: {} cases ({} with tips that cannot be ground), {} at a time, {} thread(s) a case, into {}\n", plan.cases.size(),
               infeasible.size(), workers.jobs, workers.threads_per_case, dir.string());
  run_sweep_with_workers(plan, dir, workers);
  write_and_print_table(dir, plan);
}

}  // namespace

void add_sweep_command(CLI::App& app) {
  auto o = std::make_shared<SweepOptions>();
  CLI::App* c = app.add_subcommand("sweep", "Run a design sweep: each case the whole pipeline (CAD -> mesh -> particles -> insertion), one table "
                                            "(docs/sweeps.md)");
  c->add_option("file", o->file, "Sweep file (JSON): base scene, design variables, design")->required();
  c->add_option("--out", o->out_dir, "The sweep's folder (created; a folder of the same sweep goes on where it stopped)");
  c->add_option("--jobs", o->jobs, "Worker processes on this machine (default 1)");
  c->add_option("--mpi", o->mpi_ranks,
                "Run on N MPI ranks (N - 1 workers) by starting mpirun itself, so that Ctrl-C exits 130 as with --jobs "
                "(`mpirun -n N needle sweep` exits 1 when interrupted; docs/sweeps.md)");
  c->add_option("--threads", o->threads, "Worker threads of each case (default: the cores shared among the jobs)")->check(count_check());
  c->add_option("--task-index", o->task_index, "Run only this case (a batch array's task; default: SLURM_ARRAY_TASK_ID when set)")
      ->check(count_check());
  c->add_flag("--collect", o->collect, "Build the table from the cases done in --out (after a batch array)");
  c->add_flag("--count", o->count, "Print the number of cases and exit (for sbatch --array=0-(N-1))");
  c->add_flag("--quiet", o->quiet, "No progress lines");
  add_allow_other_code_flag(c, o->allow_other_code);
  c->footer("Exit codes: 0 every case finished (or its tip cannot be ground); 3 the table is written but some cases stopped, timed out, "
            "failed or were not run; 2 bad input; 130 interrupted (the finished cases stay).");
  c->callback([o] { run(*o); });
}

}  // namespace needle
