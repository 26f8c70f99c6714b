#include "studies/run_replicas.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>

namespace needle {

const NeedleScatter* find_needle_scatter(const ReplicaScatter& scatter, const std::string& name) {
  for (const NeedleScatter& s : scatter.needles)
    if (s.name == name) return &s;
  return nullptr;
}

std::pair<double, double> deflection_range_mm(const NeedleScatter& needle) {
  if (needle.replicas_with_needle == 0 || !std::isfinite(needle.deflection_mm)) return {kNaN, kNaN};
  double lo = needle.deflection_mm, hi = needle.deflection_mm;
  for (double d : needle.replica_deflection_mm)
    if (std::isfinite(d)) lo = std::min(lo, d), hi = std::max(hi, d);
  return {lo, hi};
}

ReplicaScatter replica_scatter(const std::vector<NeedleOutcome>& runs, const std::vector<PaperTarget>& here,
                               const std::vector<ModelResults>& replicas, const std::vector<PaperReferenceNeedle>& reference) {
  ReplicaScatter out;
  for (const NeedleOutcome& r : runs) {
    NeedleScatter s;
    s.name = r.name;
    s.deflection_mm = r.deflection_mm;
    for (const ModelResults& m : replicas) {
      const NeedleOutcome* o = find_outcome(m.needles, r.name);
      const double d = o ? o->deflection_mm : kNaN;
      s.replica_deflection_mm.push_back(d);
      if (std::isfinite(d)) ++s.replicas_with_needle;
    }
    const auto [lo, hi] = deflection_range_mm(s);
    s.spread_mm = hi - lo;  // NaN without a replica
    out.needles.push_back(s);
  }

  // Each replica's runs, with this report's where it has none. A target on one needle the replica lacks, or a target
  // on several when it has none of them, did not see the replica and is not counted for it. (Counted by the needles,
  // not by whether the target's printed numbers differ: a replica may round to this report's numbers.)
  out.targets.resize(here.size());
  for (const ModelResults& m : replicas) {
    std::vector<NeedleOutcome> merged;
    std::vector<std::string> has;  // the needles the replica ran
    for (const NeedleOutcome& r : runs) {
      const NeedleOutcome* o = find_outcome(m.needles, r.name);
      const bool own = o && std::isfinite(o->deflection_mm);
      merged.push_back(own ? *o : r);
      if (own) has.push_back(r.name);
    }
    const std::vector<PaperTarget> there = evaluate_paper_targets(merged, reference);
    for (size_t i = 0; i < here.size() && i < there.size(); ++i) {
      const bool saw = there[i].needle.empty() ? !has.empty() : std::find(has.begin(), has.end(), there[i].needle) != has.end();
      if (!there[i].checked || !saw) continue;
      ++out.targets[i].checked;
      if (there[i].met)
        ++out.targets[i].met;
      else
        out.targets[i].not_met.push_back(m.label);
    }
  }
  return out;
}

std::string replica_section(const ReplicaScatter& scatter, const std::vector<ModelResults>& replicas,
                            const std::vector<PaperTarget>& targets) {
  std::vector<std::string> labels;
  for (const ModelResults& m : replicas) labels.push_back(m.label);
  std::string md = "## Run-to-run scatter: the same model in replicas\n\n";
  md += fmt::format(
      "Each replica is a `needle paper` report of this same model whose runs differ only in a numerical detail that should not "
      "matter ({}). The spread of a needle's deflection over this report and its replicas is the run-to-run scatter of that "
      "number; a target is met robustly only if it holds in every replica too. A replica's missing needles are this report's.\n\n",
      fmt::join(labels, "; "));
  md += "| needle | this report |";
  std::string rule = "|---|---|";
  for (const std::string& l : labels) md += fmt::format(" {} |", l), rule += "---|";
  md += " spread (max - min, mm) |\n" + rule + "---|\n";
  for (const NeedleScatter& s : scatter.needles) {
    md += fmt::format("| {} | {} |", s.name, fmt_mm(s.deflection_mm));
    for (const double d : s.replica_deflection_mm) md += std::isfinite(d) ? fmt::format(" {} |", fmt_mm(d)) : std::string(" |");
    md += std::isfinite(s.spread_mm) ? fmt::format(" {:.3f} |\n", s.spread_mm) : std::string(" n/a (no replica) |\n");
  }
  md += "\n| target | this report | in the replicas |\n|---|---|---|\n";
  for (size_t i = 0; i < targets.size() && i < scatter.targets.size(); ++i) {
    const PaperTarget& t = targets[i];
    const TargetInReplicas& r = scatter.targets[i];
    std::string verdict = "the same in every replica (none ran its needles, or all got its numbers)";
    if (r.checked > 0)
      verdict = r.met == r.checked ? fmt::format("met in {} of {}", r.met, r.checked)
                                   : fmt::format("**met in {} of {}** (not in: {})", r.met, r.checked, fmt::join(r.not_met, "; "));
    md += fmt::format("| {} | {} | {} |\n", t.what, !t.checked ? "not checked" : t.met ? "met" : "not met", verdict);
  }
  return md;
}

}  // namespace needle
