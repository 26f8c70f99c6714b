#pragma once
// The speed-against-error report of `needle bench insertion`: each needle run at each model level
// (runs/model_levels.h) on the same scene, its time, steps, deflection, penetration and energy error, the
// deflection's error against a stored converged reference and against the full model; a CSV, a JSON and a
// PNG of time against error.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace needle {

struct SpeedErrorCase {
  std::string needle, level, status, reason;
  double runtime_s = 0, deflection_mm = 0, max_penetration_mm = 0, max_energy_balance_error = 0;
  long coupling_steps = 0, needle_steps = 0;
  int max_particles_inside = 0;
  double error_vs_reference_mm = 0;  // NaN without a reference for the needle
  double error_vs_full_mm = 0;       // NaN without the full level's run of the needle
};

// A case from its run folder's summary.json.
SpeedErrorCase speed_error_case(const std::string& needle, const std::string& level, const nlohmann::json& summary);
// Fills the errors: against reference_mm[needle] (a JSON object of deflections; missing: NaN) and the full level's case.
void fill_errors(std::vector<SpeedErrorCase>& cases, const nlohmann::json& reference_mm);
// speed_error.csv, speed_error.json and speed_error.png in folder (each written whole or not at all).
void write_speed_error_report(const std::vector<SpeedErrorCase>& cases, const std::string& folder, const std::string& reference_source);
// The table as printed lines.
std::string speed_error_table(const std::vector<SpeedErrorCase>& cases);

}  // namespace needle
