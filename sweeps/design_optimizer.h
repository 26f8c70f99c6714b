#pragma once
// `needle optimize`: a derivative-free search (NLopt) over design variables within bounds, each evaluation one
// design case (design_case.h) in DIR/cases/eval_NNNN, so that a search started again repeats NLopt's deterministic
// sequence from the evaluations already done instead of running them again. Objectives (docs/sweeps.md):
//   deflection_target_mm t          the tip that deflects t (0: the needle that goes straight): over one variable a root,
//                                   bracketed by Boost.Math's TOMS 748 (method toms748, the default there); over several,
//                                   NLopt minimises (delta - t)^2;
//   minimize abs_deflection         minimise |delta|, optionally with groove fill >= a threshold (a COBYLA constraint).
// Writes evaluations.csv (every evaluation), optimum.json and best_recipe.json (the best tip, for `needle tip --recipe`).
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "sweeps/design_case.h"

namespace needle {

struct OptimizedVariable {
  std::string name;
  double min = 0, max = 0, start = 0, step = 0, tolerance = 0;
};

struct OptimizationProblem {
  std::string source;
  DesignBase base;
  std::vector<OptimizedVariable> variables;
  bool deflection_target = true;       // false: minimise |delta|
  double target_deflection_mm = 0;
  double groove_fill_at_least = std::nan("");  // a constraint (NaN: none)
  double sample_length_at_least_mm = std::nan("");  // a constraint on the fired cannula's sample length I_s (NaN: none)
  bool constrained() const { return std::isfinite(groove_fill_at_least) || std::isfinite(sample_length_at_least_mm); }
  // How far a finished case falls short of the constraints (0: it meets them): the sum of each one's shortfall as a share
  // of its bound (the groove fill's is a share of the groove's depth already).
  double shortfall(double groove_fill, double sample_I_s_mm) const;
  double deflection_tolerance_mm = std::nan("");  // stop once |delta - target| is below (NaN: on the variables' tolerances alone)
  std::string method;                  // toms748 (one variable, a deflection target), bobyqa, cobyla, neldermead, sbplx
  int max_evaluations = 20;
};

// InputError naming the file, line and key: unknown keys or variables, min >= max, a start outside the bounds,
// a method that cannot take the constraint, bounds whose corner tips cannot be ground.
OptimizationProblem read_optimization_file(const std::string& path);

struct OptimizationOutcome {
  std::vector<CaseResult> evaluations;
  int best = -1;                 // index into evaluations
  std::string stop_reason;       // NLopt's, in words
  bool converged = false;
  std::vector<double> bracket;   // toms748: the last bracket of the target (from, to)
};

// Runs the search into dir (created, or an earlier search of the same problem resumed). Progress on stderr unless quiet.
OptimizationOutcome optimize_design(const OptimizationProblem& problem, const std::filesystem::path& dir, int threads, bool quiet,
                                    bool allow_other_code = false);

}  // namespace needle
