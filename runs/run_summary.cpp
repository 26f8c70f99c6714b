#include "runs/run_summary.h"

#include <fmt/format.h>

#include "core/input_error.h"
#include "runs/json_file.h"
#include "solver/insertion/tissue_sample.h"

namespace needle {

RunOutcome run_outcome(const nlohmann::json& s) {
  RunOutcome o;
  o.status = s.value("status", std::string("unknown"));
  o.reason = s.value("reason", std::string());
  o.deflection_mm = number_or_nan(s, "deflection_mm");
  o.insertion_mm = number_or_nan(s, "insertion_mm");
  o.runtime_s = number_or_nan(s, "runtime_s");
  o.max_energy_balance_error = number_or_nan(s, "max_energy_balance_error");
  o.max_penetration_mm = number_or_nan(s, "max_penetration_mm");
  if (s.contains("groove") && s["groove"].is_object()) o.groove_fill = number_or_nan(s["groove"], "groove_fill");
  if (s.contains("sample") && s["sample"].is_object()) {
    o.sample_I_s_mm = sample_I_s_mm(s["sample"]);
    o.sample_contact_extent_mm = number_or_nan(s["sample"], "floor_length_mm");
  }
  o.particles_inside = s.value("particles_inside", 0L);
  o.steps = s.value("steps", 0L);
  return o;
}

double sample_I_s_mm(const nlohmann::json& sample) {
  if (sample.contains("I_s_measure")) {
    NEEDLE_REQUIRE(sample["I_s_measure"] == kSampleLengthMeasure,
                   fmt::format("summary.json: sample.I_s_measure {} is not one this build reads ({})", sample["I_s_measure"].dump(), kSampleLengthMeasure));
    return number_or_nan(sample, "I_s_mm");
  }
  return number_or_nan(sample, kSampleLengthMeasure);
}

}  // namespace needle
