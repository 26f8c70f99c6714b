#pragma once
// A study's table: every case's record (cases/<name>/case.json) in the plan's order, pending where a case has
// none yet, written as sweep.csv and sweep.json with where the deflection crosses zero, and the pictures a designer
// reads at a glance: deflection and groove fill against the first variable (one curve per value of the others),
// with the paper's needles marked when that variable is d_a; for a grid of two variables, maps of both over it.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sweeps/design_case.h"
#include "sweeps/sweep_plan.h"

namespace needle {

// Each case's record in the plan's order; a case without a done record is pending (or failed, with its reason).
std::vector<CaseResult> collect_case_records(const std::filesystem::path& dir, const std::vector<SweepCase>& cases);

// Where the deflection changes sign between two finished neighbours along one numeric variable, the others held:
// linear interpolation between them.
struct DeflectionZero {
  std::string variable;
  double value = 0;
  nlohmann::json others = nlohmann::json::object();
};
std::vector<DeflectionZero> deflection_zeros(const std::vector<std::string>& variables, const std::vector<CaseResult>& rows);

struct SweepCounts {
  int finished = 0, stopped = 0, infeasible = 0, timed_out = 0, failed = 0, pending = 0;
};
SweepCounts count_cases(const std::vector<CaseResult>& rows);

// sweep.csv, sweep.json and the plots (deflection_vs_<variable>.png, groove_fill_vs_<variable>.png; deflection_map.png and
// groove_fill_map.png over a grid of two variables), each written
// whole or not at all. reference_file: the paper's table (data/paper/reference.json), marked on d_a plots; may be empty.
void write_sweep_table(const std::filesystem::path& dir, const SweepPlan& plan, const std::vector<CaseResult>& rows,
                       const std::string& reference_file);

}  // namespace needle
