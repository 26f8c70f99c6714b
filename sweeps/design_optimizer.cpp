#include "sweeps/design_optimizer.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <fmt/format.h>
#include <functional>
#include <fstream>
#include <map>
#include <nlopt.hpp>

#include "core/input_error.h"
#include "core/interrupt.h"
#include "geometry/mesh_io.h"
#include "runs/recipe_json.h"
#include "sweeps/sweep_plan.h"
#include "sweeps/target_bracket.h"

namespace needle {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

const std::map<std::string, nlopt::algorithm>& methods() {
  static const std::map<std::string, nlopt::algorithm> m = {
      {"bobyqa", nlopt::LN_BOBYQA}, {"cobyla", nlopt::LN_COBYLA}, {"neldermead", nlopt::LN_NELDERMEAD}, {"sbplx", nlopt::LN_SBPLX}};
  return m;
}

double number_at(const JsonDocument& doc, const json& object, const std::string& key, const std::string& pointer, double fallback) {
  if (!object.contains(key)) return fallback;
  NEEDLE_REQUIRE(object.at(key).is_number(), fmt::format("{}: '{}' must be a number", doc.where(pointer + "/" + key), key));
  return object.at(key).get<double>();
}

json values_at(const std::vector<OptimizedVariable>& variables, const std::vector<double>& x) {
  json values = json::object();
  for (size_t k = 0; k < variables.size(); ++k) values[variables[k].name] = x[k];
  return values;
}

std::string result_words(nlopt::result r) {
  switch (r) {
    case nlopt::STOPVAL_REACHED: return "the deflection is within its tolerance of the target";
    case nlopt::FTOL_REACHED: return "the objective changes less than its tolerance";
    case nlopt::XTOL_REACHED: return "every variable is within its tolerance";
    case nlopt::MAXEVAL_REACHED: return "max_evaluations reached";
    case nlopt::SUCCESS: return "converged";
    default: return fmt::format("NLopt result {}", static_cast<int>(r));
  }
}

json problem_to_json(const OptimizationProblem& p) {
  json variables = json::object();
  for (const OptimizedVariable& v : p.variables)
    variables[v.name] = {{"min", v.min}, {"max", v.max}, {"start", v.start}, {"step", v.step}, {"tolerance", v.tolerance}};
  json j = design_base_to_json(p.base);
  j["variables"] = variables;
  j["objective"] = p.deflection_target ? json{{"deflection_target_mm", p.target_deflection_mm}} : json{{"minimize", "abs_deflection"}};
  if (std::isfinite(p.groove_fill_at_least)) j["objective"]["groove_fill_at_least"] = p.groove_fill_at_least;
  if (std::isfinite(p.sample_length_at_least_mm)) j["objective"]["sample_length_at_least_mm"] = p.sample_length_at_least_mm;
  j["method"] = p.method;
  j["deflection_tolerance_mm"] = std::isfinite(p.deflection_tolerance_mm) ? json(p.deflection_tolerance_mm) : json(nullptr);
  return j;  // max_evaluations left out: a search may be given more evaluations and go on
}

}  // namespace

double OptimizationProblem::shortfall(double groove_fill, double sample_I_s_mm) const {
  double share = 0;
  if (std::isfinite(groove_fill_at_least)) share += std::max(0.0, groove_fill_at_least - groove_fill);
  if (std::isfinite(sample_length_at_least_mm)) share += std::max(0.0, (sample_length_at_least_mm - sample_I_s_mm) / sample_length_at_least_mm);
  return share;
}

OptimizationProblem read_optimization_file(const std::string& path) {
  const JsonDocument doc = read_json_with_lines(path);
  OptimizationProblem p;
  p.source = path;
  p.base = read_design_base(doc);
  const json& v = doc.value;
  refuse_unknown_keys(doc, v, "", {"base", "model", "set", "variables", "objective", "method", "max_evaluations", "deflection_tolerance_mm"});
  NEEDLE_REQUIRE(v.contains("variables") && v.at("variables").is_object() && !v.at("variables").empty() && v.at("variables").size() <= 10,
                 fmt::format("{}: give 'variables': one to ten design variables, each {{\"min\": a, \"max\": b}}", doc.where("/variables")));
  for (const auto& item : v.at("variables").items()) {
    const std::string pointer = "/variables/" + json_pointer_token(item.key());
    check_variable_name(item.key(), doc.where(pointer));
    NEEDLE_REQUIRE(!p.base.settings.contains(item.key()), fmt::format("{}: '{}' is both a design variable and a fixed key of 'set'", doc.where(pointer), item.key()));
    const json& spec = item.value();
    NEEDLE_REQUIRE(spec.is_object(), fmt::format("{}: give '{}' as {{\"min\": a, \"max\": b}} (start, step and tolerance optional)", doc.where(pointer), item.key()));
    refuse_unknown_keys(doc, spec, pointer, {"min", "max", "start", "step", "tolerance"});
    OptimizedVariable x;
    x.name = item.key();
    NEEDLE_REQUIRE(spec.contains("min") && spec.contains("max"), fmt::format("{}: '{}' needs 'min' and 'max'", doc.where(pointer), x.name));
    x.min = number_at(doc, spec, "min", pointer, 0);
    x.max = number_at(doc, spec, "max", pointer, 0);
    NEEDLE_REQUIRE(x.min < x.max, fmt::format("{}: the bounds of '{}' contradict each other: min {:g} is not below max {:g}", doc.where(pointer), x.name, x.min, x.max));
    x.start = number_at(doc, spec, "start", pointer, 0.5 * (x.min + x.max));
    NEEDLE_REQUIRE(x.start >= x.min && x.start <= x.max, fmt::format("{}: start {:g} lies outside [{:g}, {:g}]", doc.where(pointer + "/start"), x.start, x.min, x.max));
    x.step = number_at(doc, spec, "step", pointer, 0.25 * (x.max - x.min));
    x.tolerance = number_at(doc, spec, "tolerance", pointer, 1e-3 * (x.max - x.min));
    NEEDLE_REQUIRE(x.step > 0 && x.tolerance > 0, fmt::format("{}: step and tolerance must be positive", doc.where(pointer)));
    p.variables.push_back(x);
  }
  NEEDLE_REQUIRE(v.contains("objective") && v.at("objective").is_object(),
                 fmt::format("{}: give 'objective': {{\"deflection_target_mm\": 0}} or {{\"minimize\": \"abs_deflection\", \"groove_fill_at_least\": 0.8}}",
                             doc.where("/objective")));
  const json& objective = v.at("objective");
  refuse_unknown_keys(doc, objective, "/objective", {"deflection_target_mm", "minimize", "groove_fill_at_least", "sample_length_at_least_mm"});
  NEEDLE_REQUIRE(objective.contains("deflection_target_mm") != objective.contains("minimize"),
                 fmt::format("{}: give one objective: deflection_target_mm or minimize", doc.where("/objective")));
  p.deflection_target = objective.contains("deflection_target_mm");
  p.target_deflection_mm = number_at(doc, objective, "deflection_target_mm", "/objective", 0);
  if (objective.contains("minimize"))
    NEEDLE_REQUIRE(objective.at("minimize") == "abs_deflection", fmt::format("{}: minimize takes \"abs_deflection\"", doc.where("/objective/minimize")));
  p.groove_fill_at_least = number_at(doc, objective, "groove_fill_at_least", "/objective", std::nan(""));
  NEEDLE_REQUIRE(std::isnan(p.groove_fill_at_least) || (p.groove_fill_at_least >= 0 && p.groove_fill_at_least <= 1),
                 fmt::format("{}: groove_fill_at_least is a share of the groove's depth, from 0 to 1", doc.where("/objective/groove_fill_at_least")));
  p.sample_length_at_least_mm = number_at(doc, objective, "sample_length_at_least_mm", "/objective", std::nan(""));
  NEEDLE_REQUIRE(std::isnan(p.sample_length_at_least_mm) || p.sample_length_at_least_mm > 0,
                 fmt::format("{}: sample_length_at_least_mm must be positive", doc.where("/objective/sample_length_at_least_mm")));
  const bool constrained = p.constrained();
  // One variable toward a deflection target is a root: bracketed (TOMS 748) it converges however rough delta(d_a) is.
  const bool root = p.deflection_target && p.variables.size() == 1 && !constrained;
  p.method = v.contains("method") && v.at("method").is_string() ? v.at("method").get<std::string>() : (constrained ? "cobyla" : root ? "toms748" : "bobyqa");
  NEEDLE_REQUIRE(methods().count(p.method) || p.method == "toms748",
                 fmt::format("{}: method must be toms748, bobyqa, cobyla, neldermead or sbplx", doc.where("/method")));
  NEEDLE_REQUIRE(p.method != "toms748" || root,
                 fmt::format("{}: toms748 finds where one variable makes the deflection its target: one variable, deflection_target_mm, no constraint",
                             doc.where("/method")));
  NEEDLE_REQUIRE(!constrained || p.method == "cobyla",
                 fmt::format("{}: {} takes no constraint: a constraint (groove_fill_at_least, sample_length_at_least_mm) needs method cobyla",
                             doc.where("/method"), p.method));
  p.max_evaluations = static_cast<int>(number_at(doc, v, "max_evaluations", "", 20));
  NEEDLE_REQUIRE(p.max_evaluations >= 1 && p.max_evaluations <= 1000 && number_at(doc, v, "max_evaluations", "", 20) == p.max_evaluations,
                 fmt::format("{}: max_evaluations must be a whole number from 1 to 1000", doc.where("/max_evaluations")));
  p.deflection_tolerance_mm = number_at(doc, v, "deflection_tolerance_mm", "", std::nan(""));
  NEEDLE_REQUIRE(std::isnan(p.deflection_tolerance_mm) || (p.deflection_tolerance_mm > 0 && p.deflection_target),
                 fmt::format("{}: deflection_tolerance_mm must be positive, with the objective deflection_target_mm", doc.where("/deflection_tolerance_mm")));
  // Every corner of the bounds (and the start) must be a tip that can be ground and a scene that can be set up.
  const size_t n = p.variables.size();
  std::vector<std::vector<double>> points;
  for (size_t corner = 0; corner < (size_t{1} << n); ++corner) {
    std::vector<double> x(n);
    for (size_t k = 0; k < n; ++k) x[k] = (corner >> k) & 1 ? p.variables[k].max : p.variables[k].min;
    points.push_back(x);
  }
  std::vector<double> start(n);
  for (size_t k = 0; k < n; ++k) start[k] = p.variables[k].start;
  points.push_back(start);
  for (const std::vector<double>& x : points) {
    const json values = values_at(p.variables, x);
    CaseSetup setup;
    try {
      setup = case_setup(p.base, values);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: at {}: {}", path, describe_values(values), e.what()));
    }
    NEEDLE_REQUIRE(std::isnan(p.sample_length_at_least_mm) || setup.scene.cannula_firing.enabled,
                   fmt::format("{}: sample_length_at_least_mm needs the sample, which the runs take only when they fire the cannula: set "
                               "\"cannula.firing.enabled\": true in \"set\" (or the base scene)",
                               doc.where("/objective/sample_length_at_least_mm")));
    const std::string reason = tip_infeasibility(setup);
    NEEDLE_REQUIRE(reason.empty(), fmt::format("{}: the bounds take in a tip that cannot be ground, at {}: {}", doc.where("/variables"), describe_values(values), reason));
  }
  return p;
}

OptimizationOutcome optimize_design(const OptimizationProblem& p, const fs::path& dir, int threads, bool quiet, bool allow_other_code) {
  claim_study_folder(dir, "optimize_plan.json", problem_to_json(p), allow_other_code);
  // Only once the folder is claimed: an --out that cannot be used gets its one line and nothing before it.
  if (!quiet)
    fmt::print(stderr, "optimize: {} over {} variable(s), at most {} evaluations, into {}\n", p.method, p.variables.size(), p.max_evaluations,
               dir.string());
  const size_t n = p.variables.size();
  OptimizationOutcome outcome;
  std::map<std::string, size_t> seen;  // the values' JSON -> evaluation
  std::string stop_reason;
  const bool constrained = p.constrained();
  InterruptWatch watch;
  auto evaluate = [&](const std::vector<double>& x) -> const CaseResult& {
    const json values = values_at(p.variables, x);
    const auto known = seen.find(values.dump());
    if (known != seen.end()) return outcome.evaluations[known->second];
    if (watch.signal()) throw Interrupted(watch.signal(), fmt::format("the search was interrupted ({}): its evaluations stay in {}; the same command goes on from there",
                                                                       signal_name(watch.signal()), dir.string()));
    const int index = static_cast<int>(outcome.evaluations.size());
    const std::string name = fmt::format("eval_{:04d}", index);
    const auto start = std::chrono::steady_clock::now();
    std::optional<CaseResult> r = read_done_case(dir, name, values);
    const bool reused = r.has_value();
    if (!r) r = run_design_case(p.base, index, name, values, dir, threads, true);
    outcome.evaluations.push_back(*r);
    seen[values.dump()] = outcome.evaluations.size() - 1;
    if (!quiet)
      fmt::print(stderr, "optimize: {} ({}): {}{} in {:.0f} s\n", name, describe_values(values),
                 r->status == "finished" ? finished_case_words(*r)
                                         : fmt::format("{}: {}", r->status, r->reason),
                 reused ? " (done before: reused)" : "", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    return outcome.evaluations.back();
  };
  auto objective_of = [&](const CaseResult& r) {
    return p.deflection_target ? (r.deflection_mm - p.target_deflection_mm) * (r.deflection_mm - p.target_deflection_mm) : std::abs(r.deflection_mm);
  };
  // An exception inside NLopt's callback would reach us as its own "nlopt failure": keep it, stop NLopt, rethrow it.
  std::exception_ptr failure;
  using Callback = std::function<double(const std::vector<double>&)>;
  auto finished_case = [&](const std::vector<double>& x) -> const CaseResult& {
    try {
      const CaseResult& r = evaluate(x);
      if (r.status == "finished") return r;
      stop_reason = fmt::format("{} {}: {}", r.name, r.status, r.reason);
    } catch (...) {
      failure = std::current_exception();
    }
    throw nlopt::forced_stop();
  };
  Callback objective = [&](const std::vector<double>& x) { return objective_of(finished_case(x)); };
  // <= 0: fills enough; takes a long enough sample.
  Callback fill_constraint = [&](const std::vector<double>& x) { return p.groove_fill_at_least - finished_case(x).groove_fill; };
  Callback sample_constraint = [&](const std::vector<double>& x) {
    return (p.sample_length_at_least_mm - finished_case(x).sample_I_s_mm) / p.sample_length_at_least_mm;
  };
  if (p.method == "toms748") {
    const OptimizedVariable& x = p.variables.front();
    const auto miss = [&](double at) {
      const CaseResult& r = evaluate({at});
      if (r.status != "finished") {
        stop_reason = fmt::format("{} {}: {}", r.name, r.status, r.reason);
        throw nlopt::forced_stop();
      }
      return r.deflection_mm - p.target_deflection_mm;
    };
    try {
      const TargetBracket found = bracket_target(miss, x.name, x.min, x.max, x.tolerance, p.deflection_tolerance_mm, p.max_evaluations);
      outcome.converged = found.converged;
      outcome.stop_reason = found.stop_reason;
      if (std::isfinite(found.from)) outcome.bracket = {found.from, found.to};
    } catch (const nlopt::forced_stop&) {
      outcome.stop_reason = "an evaluation did not finish: " + stop_reason;
    }
  }
  auto trampoline = [](const std::vector<double>& x, std::vector<double>&, void* data) { return (*static_cast<Callback*>(data))(x); };
  nlopt::opt opt(methods().count(p.method) ? methods().at(p.method) : nlopt::LN_BOBYQA, static_cast<unsigned>(n));
  std::vector<double> lower(n), upper(n), step(n), tolerance(n), x(n);
  for (size_t k = 0; k < n; ++k) {
    lower[k] = p.variables[k].min;
    upper[k] = p.variables[k].max;
    step[k] = p.variables[k].step;
    tolerance[k] = p.variables[k].tolerance;
    x[k] = p.variables[k].start;
  }
  opt.set_lower_bounds(lower);
  opt.set_upper_bounds(upper);
  opt.set_initial_step(step);
  opt.set_xtol_abs(tolerance);
  opt.set_maxeval(p.max_evaluations);
  if (std::isfinite(p.deflection_tolerance_mm)) opt.set_stopval(p.deflection_tolerance_mm * p.deflection_tolerance_mm);
  opt.set_min_objective(trampoline, &objective);
  if (std::isfinite(p.groove_fill_at_least)) opt.add_inequality_constraint(trampoline, &fill_constraint, 1e-3);
  if (std::isfinite(p.sample_length_at_least_mm)) opt.add_inequality_constraint(trampoline, &sample_constraint, 1e-3);
  double value = 0;
  try {
    if (p.method == "toms748") throw nlopt::forced_stop();  // done above
    const nlopt::result result = opt.optimize(x, value);
    outcome.stop_reason = result_words(result);
    outcome.converged = result == nlopt::STOPVAL_REACHED || result == nlopt::XTOL_REACHED || result == nlopt::FTOL_REACHED || result == nlopt::SUCCESS;
  } catch (const nlopt::forced_stop&) {
    if (failure) std::rethrow_exception(failure);
    if (p.method != "toms748") outcome.stop_reason = "an evaluation did not finish: " + stop_reason;
  } catch (const nlopt::roundoff_limited&) {
    outcome.stop_reason = "NLopt stopped at the limit of the objective's rounding";
  }
  // The best finished evaluation (meeting the constraint where there is one; else the least short of it).
  double best_violation = INFINITY, best_objective = INFINITY;
  for (size_t k = 0; k < outcome.evaluations.size(); ++k) {
    const CaseResult& r = outcome.evaluations[k];
    if (r.status != "finished") continue;
    const double violation = constrained ? p.shortfall(r.groove_fill, r.sample_I_s_mm) : 0.0;
    const double f = objective_of(r);
    if (violation < best_violation || (violation == best_violation && f < best_objective)) {
      best_violation = violation;
      best_objective = f;
      outcome.best = static_cast<int>(k);
    }
  }
  // evaluations.csv: every evaluation in NLopt's order.
  write_file_atomically((dir / "evaluations.csv").string(), [&](const std::string& scratch) {
    std::ofstream out(scratch);
    out << "evaluation,name";
    for (const OptimizedVariable& v : p.variables) out << "," << v.name;
    const bool sampled = std::isfinite(p.sample_length_at_least_mm);
    out << ",status,deflection_mm,groove_fill" << (sampled ? ",sample_I_s_mm" : "") << ",objective,runtime_s\n";
    for (const CaseResult& r : outcome.evaluations) {
      out << r.index << "," << r.name;
      for (const OptimizedVariable& v : p.variables) out << "," << fmt::format("{}", r.values.at(v.name).get<double>());
      const bool ok = r.status == "finished";
      out << "," << r.status << "," << (ok ? fmt::format("{}", r.deflection_mm) : "") << "," << (ok ? fmt::format("{}", r.groove_fill) : "")
          << (sampled ? "," + (ok ? fmt::format("{}", r.sample_I_s_mm) : std::string()) : std::string()) << "," << (ok ? fmt::format("{}", objective_of(r)) : "") << "," << (std::isfinite(r.runtime_s) ? fmt::format("{:.3f}", r.runtime_s) : "") << "\n";
    }
  });
  json optimum{{"problem", p.source},
               {"method", p.method},
               {"evaluations", outcome.evaluations.size()},
               {"stop_reason", outcome.stop_reason},
               {"converged", outcome.converged}};
  if (outcome.bracket.size() == 2) optimum["bracket"] = {{"variable", p.variables.front().name}, {"from", outcome.bracket[0]}, {"to", outcome.bracket[1]}};
  if (outcome.best >= 0) {
    const CaseResult& best = outcome.evaluations[static_cast<size_t>(outcome.best)];
    optimum["best"] = case_result_to_json(best);
    optimum["best"]["objective"] = objective_of(best);
    if (std::isfinite(p.groove_fill_at_least)) optimum["best"]["meets_groove_fill"] = best.groove_fill >= p.groove_fill_at_least;
    if (std::isfinite(p.sample_length_at_least_mm)) optimum["best"]["meets_sample_length"] = best.sample_I_s_mm >= p.sample_length_at_least_mm;
    const std::optional<GrindingRecipe> recipe = case_recipe(case_setup(p.base, best.values));
    if (recipe) {
      write_file_atomically((dir / "best_recipe.json").string(),
                            [&](const std::string& scratch) { std::ofstream(scratch) << recipe_to_json(*recipe).dump(2) << "\n"; });
      optimum["best_recipe"] = "best_recipe.json";
    }
  }
  write_file_atomically((dir / "optimum.json").string(), [&](const std::string& scratch) { std::ofstream(scratch) << optimum.dump(2) << "\n"; });
  return outcome;
}

}  // namespace needle
