#pragma once
// The paper's other observations, from its LS-DYNA model (Figs. 6 and 7, Section III.A; shared/SPEC.md): the minimum
// principal strain on the top of SB's tip, below each tip and in the groove, at insertion L = 4.8 and 30 mm; the
// deflection at L = 4.8 mm; whether the tissue touches the groove. They are a model's outputs read off contour plots,
// not measurements: the report sets ours beside them to diagnose, not as targets. Ours come from each run's
// summary.json (`strain_probes`, solver/insertion/strain_probes.h; `groove.floor_contact_fraction`).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace needle {

// One needle's run as the observations table reads it: its name and summary.json.
struct ObservedRun {
  std::string name;
  nlohmann::json summary;
};

// The report's section "The paper's other observations": a Markdown table, one row per observation of each needle
// the paper makes one for, the paper's value beside ours; "" when no run holds strain probes (runs older than them).
std::string paper_observations_section(const std::vector<ObservedRun>& runs);

// The same rows as JSON (results.json's `observations`): needle, what, where, paper, ours.
nlohmann::json paper_observations_json(const std::vector<ObservedRun>& runs);

}  // namespace needle
