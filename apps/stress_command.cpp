// `needle stress --out DIR`: the hard-case suite, run as a sweep of explicit cases (data/stress/hard_cases.json, or
// the short one CI runs) with a time limit for each case, and its report (stress.md) beside the sweep's table.
#include "apps/stress_command.h"

#include <fmt/format.h>
#include <memory>
#include <stdexcept>

#include "apps/cli_checks.h"
#include "core/input_error.h"
#include "core/parallel.h"
#include "sweeps/stress_report.h"
#include "sweeps/sweep_executor.h"
#include "sweeps/sweep_plan.h"
#include "sweeps/sweep_table.h"
#include "runs/writer_lock.h"

#ifndef NEEDLE_DATA_DIR
#define NEEDLE_DATA_DIR "data"
#endif

namespace needle {
namespace fs = std::filesystem;
namespace {

struct StressOptions {
  std::string out_dir, suite;
  bool short_suite = false, quiet = false, allow_other_code = false;
  int jobs = 2;
  double case_time_limit_s = 0;
};

void run(const StressOptions& o) {
  const std::string suite = !o.suite.empty() ? o.suite
                            : std::string(NEEDLE_DATA_DIR) + (o.short_suite ? "/stress/hard_cases_short.json" : "/stress/hard_cases.json");
  NEEDLE_REQUIRE(o.suite.empty() || !o.short_suite, "give --suite or --short, not both");
  NEEDLE_REQUIRE(o.jobs >= 1 && o.jobs <= 256, fmt::format("--jobs must be from 1 to 256 (got {})", o.jobs));
  NEEDLE_REQUIRE(o.case_time_limit_s >= 0,
                 "--case-time-limit-s must be positive, or 0 for the suite's default (900 s; 120 s with --short)");
  const SweepPlan plan = read_sweep_file(suite);
  const fs::path dir(o.out_dir);
  const auto lock = lock_output_folder(dir);
  check_sweep_cases(plan);
  claim_study_folder(dir, "sweep_plan.json", sweep_plan_to_json(plan), o.allow_other_code);
  SweepWorkers workers;
  workers.sweep_file = fs::absolute(suite).string();
  workers.jobs = o.jobs;
  workers.threads_per_case = std::max(1, hardware_threads() / o.jobs);
  workers.quiet = o.quiet;
  workers.case_time_limit_s = o.case_time_limit_s > 0 ? o.case_time_limit_s : (o.short_suite ? 120.0 : 900.0);
  if (!o.quiet)
    fmt::print(stderr, "stress: {} hard cases from {}, {} at a time, at most {:g} s a case, into {}\n", plan.cases.size(), suite, workers.jobs,
               workers.case_time_limit_s, dir.string());
  run_sweep_with_workers(plan, dir, workers);
  const std::vector<CaseResult> rows = collect_case_records(dir, plan.cases);
  write_sweep_table(dir, plan, rows, "");
  const int findings = write_stress_report(dir, suite, rows);
  const SweepCounts c = count_cases(rows);
  fmt::print("stress: {} cases: {} finished, {} stopped by a monitor, {} timed out, {} failed; report {}\n", rows.size(), c.finished, c.stopped,
             c.timed_out, c.failed, (dir / "stress.md").string());
  if (findings > 0) throw std::runtime_error(fmt::format("the hard-case suite has {} finding(s): see {}", findings, (dir / "stress.md").string()));
}

}  // namespace

void add_stress_command(CLI::App& app) {
  auto o = std::make_shared<StressOptions>();
  CLI::App* c = app.add_subcommand("stress", "Run the hard-case suite: corners of the parameter space, each finished or stopped by its monitor, "
                                             "never NaN or a hang (docs/sweeps.md)");
  c->add_option("--out", o->out_dir, "The suite's folder (created; a folder of the same suite goes on where it stopped)")->required();
  c->add_flag("--short", o->short_suite, "The short suite CI runs (six cases, 1 mm, seconds)");
  c->add_option("--suite", o->suite, "Another suite: a sweep file of explicit cases");
  c->add_option("--jobs", o->jobs, "Worker processes (default 2)");
  c->add_option("--case-time-limit-s", o->case_time_limit_s, "Stop a case that runs longer and record it as timed out (0: the suite's default, 900 s; 120 s with --short)");
  c->add_flag("--quiet", o->quiet, "No progress lines");
  add_allow_other_code_flag(c, o->allow_other_code);
  c->callback([o] { run(*o); });
}

}  // namespace needle
