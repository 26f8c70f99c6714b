#pragma once
// The entries of a run's summary.json that every reader of finished runs wants (the paper's report, the
// speed-against-error table, a design study's case): one place that knows their keys.
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

namespace needle {

struct RunOutcome {
  std::string status = "unknown", reason;  // finished, stopped, interrupted (status "unknown": the key is missing)
  double deflection_mm = std::nan(""), insertion_mm = std::nan(""), runtime_s = std::nan("");
  double max_energy_balance_error = std::nan(""), max_penetration_mm = std::nan("");
  double groove_fill = std::nan("");  // NaN without a groove
  double sample_I_s_mm = std::nan("");  // the fired cannula's sample length (summary "sample"; NaN: no firing)
  double sample_contact_extent_mm = std::nan("");  // beside it: the extent of the tissue the contact lists on the floor
  long particles_inside = 0, steps = 0;
};

// Missing numbers read as NaN (or 0 for the counts).
RunOutcome run_outcome(const nlohmann::json& summary);

// A summary's "sample" I_s: the floor its nearest layer covers (I_s_measure "floor_layer_covered_mm"). Summaries written
// before 2026-11-29 have no I_s_measure and held the contact's extent in I_s_mm: their floor_layer_covered_mm is read
// instead, and one older still, without it, has no I_s by today's measure (NaN).
double sample_I_s_mm(const nlohmann::json& sample);

}  // namespace needle
