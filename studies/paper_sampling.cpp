#include "studies/paper_sampling.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

namespace needle {

namespace {

const SampledNeedle* find(const std::vector<SampledNeedle>& needles, const std::string& name) {
  for (const SampledNeedle& n : needles)
    if (n.name == name && std::isfinite(n.I_s_mm)) return &n;
  return nullptr;
}

std::string number(double x, const char* format) { return std::isfinite(x) ? fmt::format(fmt::runtime(format), x) : "—"; }

}  // namespace

SamplingVerdict judge_sampling(const std::vector<SampledNeedle>& needles) {
  SamplingVerdict v;
  const SampledNeedle *sb = find(needles, "SB"), *lmb = find(needles, "LMB"), *amb = find(needles, "AMB"), *hmb = find(needles, "HMB");
  if (!sb || !lmb || !amb || !hmb || !(sb->I_s_mm > 0)) return v;
  v.ranked = sb->I_s_mm > amb->I_s_mm && lmb->I_s_mm > amb->I_s_mm && amb->I_s_mm > hmb->I_s_mm;
  v.ratios_within = true;
  for (const SampledNeedle* n : {sb, lmb, amb, hmb}) {
    if (!std::isfinite(n->measured_I_s_mm) || !std::isfinite(sb->measured_I_s_mm)) {
      v.ratios_within = false;
      continue;
    }
    const double miss = std::abs(n->I_s_mm / sb->I_s_mm - n->measured_I_s_mm / sb->measured_I_s_mm);
    v.worst_ratio_miss = std::max(v.worst_ratio_miss, miss);
    v.ratios_within = v.ratios_within && miss <= SamplingVerdict::kRatioTolerance;
  }
  return v;
}

std::string sampling_section(const std::vector<SampledNeedle>& needles, const std::string& tissue) {
  if (std::none_of(needles.begin(), needles.end(), [](const SampledNeedle& n) { return std::isfinite(n.I_s_mm); })) return "";
  const SampledNeedle* sb = find(needles, "SB");
  std::string md = "## The sample: the cannula fired over the groove\n\n";
  md += fmt::format(
      "Each run fired the cannula over the groove after its insertion (`--fire-cannula`, docs/insertion.md#the-sample-firing-the-cannula). "
      "I_s is the extent along the axis of the tissue it enclosed that touches the groove floor when it stops (the issue's "
      "definition; summary.json also has the extent of the tissue that touched the floor at any time during the stroke). The runs' tissue: "
      "{}. The measured lengths are the paper's, in ex-vivo chicken breast (ten each, pooled SD about 1.6 mm): the comparison is of "
      "the PVC model with chicken breast, so the ratios to SB, not the millimetres, are what it can be judged on.\n\n",
      tissue.empty() ? "the scene's" : tissue);
  md += "| needle | I_s predicted (mm) | ratio to SB | I_s measured (mm) | measured ratio | particles on the floor | floor covered (mm) | "
        "floor layer: extent / covered (mm) | floor contact before firing | whole sample length (mm) | volume (mm³) | volume's ratio to SB |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const SampledNeedle& n : needles) {
    const double ratio = sb && sb->I_s_mm > 0 ? n.I_s_mm / sb->I_s_mm : std::nan("");
    const double measured_ratio = sb && std::isfinite(sb->measured_I_s_mm) ? n.measured_I_s_mm / sb->measured_I_s_mm : std::nan("");
    const double volume_ratio = sb && sb->volume_mm3 > 0 ? n.volume_mm3 / sb->volume_mm3 : std::nan("");
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} / {} | {} | {} | {} | {} |\n", n.name, number(n.I_s_mm, "{:.2f}"),
                      number(ratio, "{:.2f}"), number(n.measured_I_s_mm, "{:.1f}"), number(measured_ratio, "{:.2f}"), n.floor_particles,
                      number(n.floor_covered_mm, "{:.2f}"), number(n.floor_layer_length_mm, "{:.2f}"), number(n.floor_layer_covered_mm, "{:.2f}"),
                      number(n.floor_contact_before, "{:.3f}"),
                      number(n.length_mm, "{:.2f}"), number(n.volume_mm3, "{:.3f}"), number(volume_ratio, "{:.2f}"));
  }
  std::vector<const SampledNeedle*> ranked;
  for (const SampledNeedle& n : needles)
    if (std::isfinite(n.I_s_mm)) ranked.push_back(&n);
  std::stable_sort(ranked.begin(), ranked.end(), [](const SampledNeedle* a, const SampledNeedle* b) { return a->I_s_mm > b->I_s_mm; });
  std::string order;
  for (const SampledNeedle* n : ranked) order += (order.empty() ? "" : " > ") + n->name;
  md += fmt::format("\nRanked by predicted I_s (longest first): {}. Measured: LMB (12.9) > SB (12.5) > AMB (9.9) > HMB (8.6) mm. I_s is the "
                    "extent between the outermost floor-touching particles: where a few of them lie near the groove's ends it reads "
                    "nearly the whole groove however little of the floor is covered (the floor-covered length and the particle count "
                    "say how much rests on how few). The kinematic contact lists a particle as touching only in a step it pushes it "
                    "back; the floor layer counts, by geometry, every particle whose centre lies within the contact's skin and a "
                    "quarter spacing of the floor. The floor layer was added after the first results on these four needles: a "
                    "measure chosen after looking, not a prediction, and the targets below are judged on I_s "
                    "(docs/notebook/sampling.md).\n\n",
                    order);
  const SamplingVerdict v = judge_sampling(needles);
  md += fmt::format("| target | verdict |\n|---|---|\n| SB and LMB above AMB, AMB above HMB | {} |\n| each ratio to SB within {:.2f} of the "
                    "measured (1.00, 1.03, 0.79, 0.69) | {} (worst miss {:.2f}) |\n\n",
                    v.ranked ? "met" : "missed", SamplingVerdict::kRatioTolerance, v.ratios_within ? "met" : "missed", v.worst_ratio_miss);
  return md;
}

}  // namespace needle
