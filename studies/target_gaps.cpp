#include "studies/target_gaps.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

namespace needle {

namespace {

const NeedleEndLoads* find_loads(const std::vector<NeedleEndLoads>& loads, const std::string& name) {
  for (const NeedleEndLoads& l : loads)
    if (l.name == name) return &l;
  return nullptr;
}

// Which load at the end points the way the needle misses (up for a positive error), and what it is.
std::string load_sentence(const NeedleEndLoads& l, double error_mm) {
  const double sign = error_mm > 0 ? 1.0 : -1.0;
  struct Part {
    const char* name;
    double force_N;
    const char* mechanism;
  };
  const Part parts[] = {
      {"shaft", l.shaft_N,
       sign > 0 ? "the tissue cut below tip point A stays pressed down under the whole inserted shaft and pushes it up"
                : "the tissue holds the shaft down in the channel the tip cut"},
      {"groove", l.groove_N,
       sign > 0 ? "the tissue in the groove pushes it up" : "the tissue above the cut rebounds into the groove and presses its floor down"},
      {"tip facets", l.tip_facets_N,
       sign > 0 ? "the tissue the tip's lower facets press down pushes the tip up" : "the tissue the tip's upper facets lift presses the tip down"},
  };
  const Part* largest = nullptr;
  for (const Part& p : parts)
    if (std::isfinite(p.force_N) && sign * p.force_N > 0 && (!largest || sign * p.force_N > sign * largest->force_N)) largest = &p;
  std::string s = fmt::format("At the end the tissue's y force on it is {:+.3f} N on the shaft, {:+.3f} N on the groove and {:+.3f} N on the tip "
                              "facets (+: up). ",
                              l.shaft_N, l.groove_N, l.tip_facets_N);
  if (!largest)
    return s + fmt::format("None of them points {}: the needle follows the channel its tip cut earlier in the insertion.", sign > 0 ? "up" : "down");
  return s + fmt::format("The largest load {} is the {}'s: {}.", sign > 0 ? "upward" : "downward", largest->name, largest->mechanism);
}

}  // namespace

std::string target_gaps_section(const TargetGapInput& in) {
  const PaperReferenceNeedle* ref_sb = find_reference(in.reference, "SB");
  const NeedleOutcome* sb = find_outcome(in.runs, "SB");
  std::string items;
  for (size_t i = 0; i < in.targets.size(); ++i) {
    const PaperTarget& t = in.targets[i];
    if (t.needle.empty() || !t.checked) continue;
    const NeedleOutcome* run = find_outcome(in.runs, t.needle);
    const PaperReferenceNeedle* ref = find_reference(in.reference, t.needle);
    if (!run || !ref) continue;
    const TargetInReplicas* there = in.scatter && i < in.scatter->targets.size() ? &in.scatter->targets[i] : nullptr;
    const bool missed_in_replica = there && there->met < there->checked;
    if (t.met && !missed_in_replica) continue;

    std::string item = fmt::format("- **{}** ends at {:+.3f} mm against the experiment's {:+.2f}: {:+.3f} mm off, {}.", t.needle,
                                   run->deflection_mm, ref->deflection_experiment_mm, t.error_mm, t.allowance);
    // Chance or model: the run-to-run scatter against the margin.
    const NeedleScatter* scatter = in.scatter ? find_needle_scatter(*in.scatter, t.needle) : nullptr;
    if (scatter && !std::isfinite(scatter->spread_mm)) scatter = nullptr;  // no replica ran this needle
    const double margin = std::abs(t.error_mm) - t.allowed_mm;  // > 0: missed by this much
    if (scatter) {
      if (t.met)
        item += fmt::format(" It holds here by {:.3f} mm, but its run-to-run spread is {:.3f} mm and it misses in {} of {} replicas: "
                            "met by chance, not by the model.",
                            -margin, scatter->spread_mm, there->checked - there->met, there->checked);
      else if (scatter->spread_mm < margin)
        item += fmt::format(" Its run-to-run spread, {:.3f} mm, is less than the {:.3f} mm by which it misses: the miss is the model's, "
                            "not chance.",
                            scatter->spread_mm, margin);
      else
        item += fmt::format(" Its run-to-run spread, {:.3f} mm, is as large as the {:.3f} mm by which it misses: this miss may be chance.",
                            scatter->spread_mm, margin);
    } else if (!t.met) {
      item += " (No replica here to tell the miss from run-to-run scatter.)";
    }
    if (const NeedleEndLoads* l = find_loads(in.loads, t.needle)) item += " " + load_sentence(*l, t.error_mm);
    // Not a matter of E: the ratio to SB.
    if (t.needle != "SB" && sb && ref_sb && std::isfinite(run->deflection_mm / sb->deflection_mm) && ref_sb->deflection_experiment_mm != 0) {
      const double ours = run->deflection_mm / sb->deflection_mm, experiment = ref->deflection_experiment_mm / ref_sb->deflection_experiment_mm;
      const double at_measured_sb_mm = (ours - experiment) * ref_sb->deflection_experiment_mm;
      item += fmt::format(" Its delta / delta_SB is {:+.2f} here against the experiment's {:+.2f}. One E scales every needle's delta alike "
                          "to first order, so with SB at its measured delta this ratio leaves {} {:+.3f} mm off: ",
                          ours, experiment, t.needle, at_measured_sb_mm);
      item += std::abs(at_measured_sb_mm) > t.allowed_mm ? "no E calibrated on SB closes the gap."
              : t.met                                    ? "within the allowed error."
                                                         : "within the allowed error, so the miss comes from SB's own offset, not the ratio.";
      if (in.models.size() > 1) {
        const auto [lo, hi] = ratio_to_sb_span(in.models, t.needle);
        if (std::isfinite(lo))
          item += fmt::format(" Over the {} models compared in this report (this one included; below) it spans {:+.2f} to {:+.2f}: {}.",
                              in.models.size(), lo, hi,
                              experiment >= lo && experiment <= hi ? "the experiment's lies inside, so a model choice moves it across the measurement"
                                                                   : "none of them reaches the experiment's");
      }
    }
    items += item + "\n";
  }
  if (items.empty()) return "";
  return "## Where a deflection target is missed, and why\n\n" + items;
}

}  // namespace needle
