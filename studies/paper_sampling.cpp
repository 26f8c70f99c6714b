#include "studies/paper_sampling.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

namespace needle {

namespace {

const SampledNeedle* find(const std::vector<SampledNeedle>& needles, const std::string& name, double SampledNeedle::*length) {
  for (const SampledNeedle& n : needles)
    if (n.name == name && std::isfinite(n.*length)) return &n;
  return nullptr;
}

std::string number(double x, const char* format) { return std::isfinite(x) ? fmt::format(fmt::runtime(format), x) : "—"; }

double ratio_to_sb(const std::vector<SampledNeedle>& needles, const std::string& name, double SampledNeedle::*length) {
  const SampledNeedle *sb = find(needles, "SB", length), *n = find(needles, name, length);
  return sb && n && sb->*length > 0 ? n->*length / sb->*length : std::nan("");
}

// A replica's needles with this report's measured lengths.
std::vector<SampledNeedle> with_measured(const std::vector<SampledNeedle>& replica, const std::vector<SampledNeedle>& report) {
  std::vector<SampledNeedle> out = replica;
  for (SampledNeedle& n : out) {
    n.measured_I_s_mm = std::nan("");
    for (const SampledNeedle& r : report)
      if (r.name == n.name) n.measured_I_s_mm = r.measured_I_s_mm;
  }
  return out;
}

std::string verdict_words(const SamplingVerdict& v) {
  return fmt::format("{}, {} (worst {:.2f})", v.ranked ? "ranked" : "**not ranked**", v.ratios_within ? "ratios within" : "**ratios missed**",
                     v.worst_ratio_miss);
}

}  // namespace

SamplingVerdict judge_sampling(const std::vector<SampledNeedle>& needles, double SampledNeedle::*length) {
  SamplingVerdict v;
  const SampledNeedle *sb = find(needles, "SB", length), *lmb = find(needles, "LMB", length), *amb = find(needles, "AMB", length),
                      *hmb = find(needles, "HMB", length);
  if (!sb || !lmb || !amb || !hmb || !(sb->*length > 0)) return v;
  v.ranked = sb->*length > amb->*length && lmb->*length > amb->*length && amb->*length > hmb->*length;
  v.ratios_within = true;
  for (const SampledNeedle* n : {sb, lmb, amb, hmb}) {
    if (!std::isfinite(n->measured_I_s_mm) || !std::isfinite(sb->measured_I_s_mm)) {
      v.ratios_within = false;
      continue;
    }
    const double miss = std::abs(n->*length / sb->*length - n->measured_I_s_mm / sb->measured_I_s_mm);
    v.worst_ratio_miss = std::max(v.worst_ratio_miss, miss);
    v.ratios_within = v.ratios_within && miss <= SamplingVerdict::kRatioTolerance;
  }
  return v;
}

std::vector<SamplingLattice> judge_sampling_lattices(const std::vector<SampledNeedle>& needles, const std::vector<SampledReplica>& replicas) {
  std::vector<SamplingLattice> out{{"this report", needles, judge_sampling(needles), judge_sampling(needles, &SampledNeedle::contact_extent_mm)}};
  for (const SampledReplica& r : replicas) {
    std::vector<SampledNeedle> n = with_measured(r.needles, needles);
    bool all_four = true;
    for (const char* name : {"SB", "LMB", "AMB", "HMB"}) all_four = all_four && find(n, name, &SampledNeedle::I_s_mm);
    if (all_four) {
      const SamplingVerdict I_s = judge_sampling(n), extent = judge_sampling(n, &SampledNeedle::contact_extent_mm);
      out.push_back({r.label, std::move(n), I_s, extent});
    }
  }
  return out;
}

std::string sampling_section(const std::vector<SampledNeedle>& needles, const std::string& tissue, const std::vector<SampledReplica>& replicas) {
  if (std::none_of(needles.begin(), needles.end(), [](const SampledNeedle& n) { return std::isfinite(n.I_s_mm); })) return "";
  constexpr auto kIs = &SampledNeedle::I_s_mm;
  constexpr auto kContact = &SampledNeedle::contact_extent_mm;
  std::string md = "## The sample: the cannula fired over the groove\n\n";
  md += fmt::format(
      "Each run fired the cannula over the groove after its insertion (`--fire-cannula`, docs/insertion.md#the-sample-firing-the-cannula). "
      "**I_s is the length of groove floor the enclosed tissue rests on when the cannula stops**: the axis covered by the sample's "
      "particles whose centre lies within the contact's skin and a quarter spacing of the floor, gaps left out. The runs' tissue: {}. "
      "The measured lengths are the paper's, in ex-vivo chicken breast (ten each, pooled SD about 1.6 mm); no chicken-breast card is "
      "shipped, so the comparison is of the PVC card with chicken breast, and the ratios to SB, not the millimetres, are what it is "
      "judged on.\n\n",
      tissue.empty() ? "the scene's" : tissue);
  md += "| needle | I_s predicted (mm) | ratio to SB | I_s measured (mm) | measured ratio | particles resting on the floor | "
        "the contact's extent (mm), ratio [particles] | whole sample length (mm) | volume (mm³), ratio | floor contact before firing |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n";
  const SampledNeedle* sb = find(needles, "SB", kIs);
  for (const SampledNeedle& n : needles) {
    const double measured_ratio = sb && std::isfinite(sb->measured_I_s_mm) ? n.measured_I_s_mm / sb->measured_I_s_mm : std::nan("");
    const double volume_ratio = sb && sb->volume_mm3 > 0 ? n.volume_mm3 / sb->volume_mm3 : std::nan("");
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {}, {} [{}] | {} | {}, {} | {} |\n", n.name, number(n.I_s_mm, "{:.2f}"),
                      number(ratio_to_sb(needles, n.name, kIs), "{:.2f}"), number(n.measured_I_s_mm, "{:.1f}"), number(measured_ratio, "{:.2f}"),
                      n.floor_layer_particles, number(n.contact_extent_mm, "{:.2f}"), number(ratio_to_sb(needles, n.name, kContact), "{:.2f}"),
                      n.contact_particles, number(n.length_mm, "{:.2f}"), number(n.volume_mm3, "{:.3f}"), number(volume_ratio, "{:.2f}"),
                      number(n.floor_contact_before, "{:.3f}"));
  }
  std::vector<const SampledNeedle*> ranked;
  for (const SampledNeedle& n : needles)
    if (std::isfinite(n.I_s_mm)) ranked.push_back(&n);
  std::stable_sort(ranked.begin(), ranked.end(), [](const SampledNeedle* a, const SampledNeedle* b) { return a->I_s_mm > b->I_s_mm; });
  std::string order;
  for (const SampledNeedle* n : ranked) order += (order.empty() ? "" : " > ") + n->name;
  md += fmt::format(
      "\nRanked by predicted I_s (longest first): {}. Measured: LMB (12.9) > SB (12.5) > AMB (9.9) > HMB (8.6) mm.\n\n"
      "**How I_s came to be this length, and what that means for the verdicts.** The issue first read I_s as the extent of the "
      "enclosed tissue touching the floor. By geometry that extent is the whole groove in every needle (it cannot tell them "
      "apart); by the contact's list (the column beside) it rests on a few particles, because the kinematic contact lists a particle "
      "only in a step it pushes it back, not while it rests at the skin (on the paper's HMB, 2–4 particles, whose extent moved by 16 mm "
      "between lattice shifts). "
      "The covered length was chosen after the first three lattices had been seen, so it is a measure chosen after looking; a fourth "
      "lattice, its criterion written before its runs, was then held out and passed (docs/notebook/sampling.md). A lattice shift tests "
      "the rounding, not new needles: there is no measured length at other tips to judge the measure on.\n\n",
      order);
  const std::vector<SamplingLattice> lattices = judge_sampling_lattices(needles, replicas);
  const SamplingVerdict& v = lattices.front().I_s;
  const auto every = [&](auto pick) {
    return std::count_if(lattices.begin(), lattices.end(), [&](const SamplingLattice& l) { return pick(l); });
  };
  const long n = static_cast<long>(lattices.size());
  const long ranked_all = every([](const SamplingLattice& l) { return l.I_s.ranked; });
  const long within_all = every([](const SamplingLattice& l) { return l.I_s.ratios_within; });
  const bool with_replicas = n > 1;
  const auto in_every = [&](long met) { return with_replicas ? fmt::format(" {} of {} |", met, n) : std::string(); };
  md += fmt::format("| target (judged on I_s) | this report |{}\n|---|---|{}\n",
                    with_replicas ? fmt::format(" every lattice (this report and {} replica{}) |", n - 1, n == 2 ? "" : "s") : "", with_replicas ? "---|" : "");
  md += fmt::format("| SB and LMB above AMB, AMB above HMB | {} |{}\n", v.ranked ? "met" : "missed", in_every(ranked_all));
  md += fmt::format("| each ratio to SB within {:.2f} of the measured (1.00, 1.03, 0.79, 0.69) | {} (worst miss {:.2f}) |{}\n\n",
                    SamplingVerdict::kRatioTolerance, v.ratios_within ? "met" : "missed", v.worst_ratio_miss, in_every(within_all));
  if (with_replicas) {
    md += "Each lattice (the replicas: the same model, the particle lattice shifted), judged on I_s and, beside it, on the contact's extent:\n\n"
          "| lattice | I_s of SB (mm) | I_s ratios LMB, AMB, HMB | on I_s | the contact's extent: ratios LMB, AMB, HMB | on the contact's extent |\n"
          "|---|---|---|---|---|---|\n";
    for (const SamplingLattice& l : lattices) {
      const SampledNeedle* lattice_sb = find(l.needles, "SB", kIs);
      const auto ratios = [&](double SampledNeedle::*length) {
        return fmt::format("{}, {}, {}", number(ratio_to_sb(l.needles, "LMB", length), "{:.2f}"),
                           number(ratio_to_sb(l.needles, "AMB", length), "{:.2f}"), number(ratio_to_sb(l.needles, "HMB", length), "{:.2f}"));
      };
      md += fmt::format("| {} | {} | {} | {} | {} | {} |\n", l.label, number(lattice_sb ? lattice_sb->I_s_mm : std::nan(""), "{:.2f}"), ratios(kIs),
                        verdict_words(l.I_s), ratios(kContact), verdict_words(l.contact_extent));
    }
    md += "\n";
  }
  return md;
}

}  // namespace needle
