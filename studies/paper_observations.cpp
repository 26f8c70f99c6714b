#include "studies/paper_observations.h"

#include <cmath>
#include <fmt/format.h>

#include "runs/json_file.h"

namespace needle {
using json = nlohmann::json;

namespace {

// One observation of the paper's model: a needle, a quantity at an insertion ("early": L = 4.8 mm, "end": 30 mm).
struct Observation {
  const char* needle;
  const char* what;    // "strain", "deflection", "groove contact"
  const char* region;  // strain: tip_top, below_tip, groove
  const char* when;    // early, end
  const char* paper;   // the paper's words or number
};

// From the paper's Section III.A (Figs. 6 and 7), as shared/SPEC.md lists them.
const std::vector<Observation>& observations() {
  static const std::vector<Observation> list = {
      {"SB", "strain", "tip_top", "early", "about -1.2"},
      {"SB", "strain", "tip_top", "end", "about -1.8"},
      {"SB", "strain", "below_tip", "early", "about 0 (almost undeformed)"},
      {"SB", "strain", "groove", "end", "about -0.6"},
      {"SB", "deflection", "", "early", "almost 0 (cannula support)"},
      {"SB", "groove contact", "", "end", "contact"},
      {"LMB", "strain", "below_tip", "early", "about -0.45"},
      {"LMB", "strain", "groove", "end", "about -0.6"},
      {"LMB", "deflection", "", "early", "0"},
      {"LMB", "groove contact", "", "end", "contact"},
      {"AMB", "strain", "below_tip", "early", "about -0.6"},
      {"AMB", "strain", "below_tip", "end", "about -0.9"},
      {"AMB", "strain", "groove", "end", "about 0 (rebounded)"},
      {"AMB", "groove contact", "", "end", "almost none"},
      {"HMB", "strain", "below_tip", "early", "about -0.75"},
      {"HMB", "strain", "below_tip", "end", "about -1.20"},
      {"HMB", "groove contact", "", "end", "none, a gap"},
  };
  return list;
}

const char* region_words(const std::string& region) {
  if (region == "tip_top") return "on the top facets";
  if (region == "below_tip") return "below the tip";
  return "in the groove";
}

// Ours, as text, or "" where the run holds nothing for it.
std::string ours(const Observation& o, const json& summary) {
  const std::string what = o.what;
  if (what == "groove contact") {
    if (!summary.contains("groove") || !summary["groove"].is_object()) return "";
    const double floor = number_or_nan(summary["groove"], "floor_contact_fraction"), gap = number_or_nan(summary["groove"], "mean_gap_mm");
    return std::isfinite(floor) ? fmt::format("floor contact {:.2f}, mean gap {:.3f} mm", floor, gap) : "";
  }
  if (!summary.contains("strain_probes") || !summary["strain_probes"].contains(o.when)) return "";
  const json& probe = summary["strain_probes"][o.when];
  if (what == "deflection") return fmt::format("{:+.3f} mm at {:.1f} mm", number_or_nan(probe, "deflection_mm"), number_or_nan(probe, "insertion_mm"));
  const json& r = probe.value(o.region, json::object());
  const int particles = r.value("particles", 0);
  if (particles == 0) return "no tissue there";
  return fmt::format("{:.2f} (median {:.2f}; {} particles)", number_or_nan(r, "p05"), number_or_nan(r, "median"), particles);
}

std::string where(const Observation& o) {
  const std::string at = std::string(o.when) == "early" ? "L 4.8 mm" : "L 30 mm";
  const std::string what = o.what;
  if (what == "strain") return fmt::format("min. principal strain {}, {}", region_words(o.region), at);
  if (what == "deflection") return fmt::format("deflection, {}", at);
  return fmt::format("tissue on the groove floor, {}", at);
}

bool has_probes(const std::vector<ObservedRun>& runs) {
  for (const ObservedRun& r : runs)
    if (r.summary.contains("strain_probes")) return true;
  return false;
}

}  // namespace

json paper_observations_json(const std::vector<ObservedRun>& runs) {
  json rows = json::array();
  if (!has_probes(runs)) return rows;
  for (const ObservedRun& r : runs)
    for (const Observation& o : observations())
      if (r.name == o.needle) rows.push_back({{"needle", r.name}, {"what", where(o)}, {"paper", o.paper}, {"ours", ours(o, r.summary)}});
  return rows;
}

std::string paper_observations_section(const std::vector<ObservedRun>& runs) {
  if (!has_probes(runs)) return "";
  std::string md = "## The paper's other observations (its LS-DYNA model's, to diagnose: not targets)\n\n";
  md += "The paper reads the minimum principal strain off contour plots of its model (Figs. 6 and 7). Ours is the smallest "
        "principal elastic Hencky strain (the total log strain where the gel has not yielded) of the particles touching the "
        "top facets (on the top facets), touching the tip within 2 mm behind A and no higher than A (below the tip), or inside "
        "the groove's section (in the groove): the 5th percentile (the most compressed) and the median "
        "(solver/insertion/strain_probes.h). Early: the first record past L = 4.8 mm.\n\n";
  md += "| needle | observation | paper (LS-DYNA) | this model |\n|---|---|---|---|\n";
  for (const ObservedRun& r : runs)
    for (const Observation& o : observations()) {
      if (r.name != o.needle) continue;
      const std::string value = ours(o, r.summary);
      md += fmt::format("| {} | {} | {} | {} |\n", r.name, where(o), o.paper, value.empty() ? "not recorded" : value);
    }
  return md + "\n";
}

}  // namespace needle
