// `needle optimize FILE --out DIR`: the tip that meets an objective, found by NLopt over design variables within
// bounds; every evaluation a design case (docs/sweeps.md).
#include "apps/optimize_command.h"

#include <fmt/format.h>
#include <memory>

#include "apps/cli_checks.h"
#include "core/parallel.h"
#include "sweeps/design_optimizer.h"
#include "runs/writer_lock.h"

namespace needle {
namespace fs = std::filesystem;
namespace {

struct OptimizeOptions {
  std::string file, out_dir;
  int threads = 0;
  bool quiet = false, allow_other_code = false;
};

void run(const OptimizeOptions& o) {
  const OptimizationProblem problem = read_optimization_file(o.file);
  const int threads = o.threads > 0 ? o.threads : hardware_threads();
  const auto lock = lock_output_folder(o.out_dir);
  const OptimizationOutcome outcome = optimize_design(problem, o.out_dir, threads, o.quiet, o.allow_other_code);
  fmt::print("optimize: {} evaluations; stopped: {}\n", outcome.evaluations.size(), outcome.stop_reason);
  if (outcome.best < 0) {
    fmt::print("optimize: no evaluation finished\n");
    return;
  }
  const CaseResult& best = outcome.evaluations[static_cast<size_t>(outcome.best)];
  fmt::print("optimize: best {} ({}): {}\n", best.name, describe_values(best.values), finished_case_words(best));
  const fs::path recipe = fs::path(o.out_dir) / "best_recipe.json";
  fmt::print("optimize: evaluations {}, optimum {}{}\n", (fs::path(o.out_dir) / "evaluations.csv").string(), (fs::path(o.out_dir) / "optimum.json").string(),
             fs::exists(recipe) ? ", best tip " + recipe.string() + " (needle tip --recipe)" : "");
}

}  // namespace

void add_optimize_command(CLI::App& app) {
  auto o = std::make_shared<OptimizeOptions>();
  CLI::App* c = app.add_subcommand("optimize", "Search the design variables for the best tip with NLopt: each evaluation the whole pipeline "
                                               "(docs/sweeps.md)");
  c->add_option("file", o->file, "Optimisation file (JSON): base scene, variables with bounds, objective, method")->required();
  c->add_option("--out", o->out_dir, "The search's folder (created; a folder of the same search goes on where it stopped)")->required();
  c->add_option("--threads", o->threads, "Worker threads of each evaluation (default: all cores)")->check(count_check());
  c->add_flag("--quiet", o->quiet, "No progress lines");
  add_allow_other_code_flag(c, o->allow_other_code);
  c->callback([o] { run(*o); });
}

}  // namespace needle
