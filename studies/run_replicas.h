#pragma once
// Replicas of this report's runs (`needle paper --replica LABEL=FILE`): each is another report's results.json
// of the same model whose runs differ only in a numerical detail that should not matter, e.g. the particle
// lattice shifted against the needle's path (--tissue-entry-x-mm). Their spread is the run-to-run scatter
// of each deflection, and a target met here but not in a replica is met by chance, not by the model.
// A replica may hold fewer needles than the report; for the targets its missing needles are this report's.
#include <string>
#include <utility>
#include <vector>

#include "studies/model_comparison.h"
#include "studies/paper_results.h"

namespace needle {

// One needle's deflection here and in each replica that ran it.
struct NeedleScatter {
  std::string name;
  double deflection_mm = kNaN;              // this report's
  std::vector<double> replica_deflection_mm;  // one per replica, NaN where the replica lacks the needle
  int replicas_with_needle = 0;
  double spread_mm = kNaN;                  // max - min over this report and the replicas that ran it; NaN without any
};

// {lowest, highest} deflection over this report and the replicas that ran the needle; {NaN, NaN} without any.
std::pair<double, double> deflection_range_mm(const NeedleScatter& needle);

// Per target of evaluate_paper_targets: in how many replicas it was checked and met.
struct TargetInReplicas {
  int checked = 0, met = 0;
  std::vector<std::string> not_met;  // the labels of the replicas where it was checked and failed
};

struct ReplicaScatter {
  std::vector<NeedleScatter> needles;      // in the report's order
  std::vector<TargetInReplicas> targets;   // in evaluate_paper_targets' order
};

// The named needle's scatter, or null.
const NeedleScatter* find_needle_scatter(const ReplicaScatter& scatter, const std::string& name);

// `here` is evaluate_paper_targets of `runs`.
ReplicaScatter replica_scatter(const std::vector<NeedleOutcome>& runs, const std::vector<PaperTarget>& here,
                               const std::vector<ModelResults>& replicas, const std::vector<PaperReferenceNeedle>& reference);

// The report's section "Run-to-run scatter" (Markdown): the deflections, their spread, and each target's verdict
// in the replicas.
std::string replica_section(const ReplicaScatter& scatter, const std::vector<ModelResults>& replicas,
                            const std::vector<PaperTarget>& targets);

}  // namespace needle
