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
  // What ran beside it (its summary's "machine"; 0 and NaN for a run from before it was recorded): the threads it
  // used of the machine's cores, and the machine's 1-minute load average as it started and as it ended.
  int threads_used = 0, cores = 0;
  double load_at_start = 0, load_at_end = 0;
};

// A case from its run folder's summary.json.
SpeedErrorCase speed_error_case(const std::string& needle, const std::string& level, const nlohmann::json& summary);
// Fills the errors: against reference_mm[needle] (a JSON object of deflections; missing: NaN) and the full level's case.
void fill_errors(std::vector<SpeedErrorCase>& cases, const nlohmann::json& reference_mm);
// speed_error.csv, speed_error.json, speed_error.png and speed_error.md (the table docs/insertion.md shows, with what
// ran beside each run) in folder (each written whole or not at all).
void write_speed_error_report(const std::vector<SpeedErrorCase>& cases, const std::string& folder, const std::string& reference_source);
// The table as printed lines.
std::string speed_error_table(const std::vector<SpeedErrorCase>& cases);
// The table in Markdown, one row a case: the level, SB's and the other needles' deflections and errors, steps, time and
// what ran beside it.
std::string speed_error_markdown(const std::vector<SpeedErrorCase>& cases, const std::string& reference_source);
// "2 threads of 2 cores, load 0.1 at the start, 2.1 at the end" (or "not recorded").
std::string beside_words(const SpeedErrorCase& c);

}  // namespace needle
