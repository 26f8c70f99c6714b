#pragma once
// Why a deflection target of the paper's report is missed (issue 7: "if a target is not met, the report says so
// and why, with the numbers"). For each needle whose target fails here, or holds here but not in every replica:
// how far off it is against what is allowed; whether the run-to-run scatter or the model accounts for it; which
// load at the end of insertion points the way of the miss; its delta / delta_SB against the experiment's (one E
// scales every needle alike to first order, so calibrating on SB cannot close a wrong ratio); and whether any
// compared model reaches the experiment's ratio.
#include <string>
#include <vector>

#include "studies/model_comparison.h"
#include "studies/paper_results.h"
#include "studies/run_replicas.h"

namespace needle {

// The y force of the tissue on a needle's parts at the end of insertion (N, + up).
struct NeedleEndLoads {
  std::string name;
  double tip_facets_N = kNaN, groove_N = kNaN, shaft_N = kNaN;
};

struct TargetGapInput {
  std::vector<PaperTarget> targets;            // evaluate_paper_targets of this report's runs
  std::vector<NeedleOutcome> runs;             // this report's
  std::vector<NeedleEndLoads> loads;           // this report's, where its runs recorded them
  std::vector<ModelResults> models;            // this report first, then the compared ones; may be empty
  const ReplicaScatter* scatter = nullptr;     // with its replicas' verdicts, or null without replicas
  std::vector<PaperReferenceNeedle> reference;
};

// The report's section (Markdown, one item a line), or "" when every deflection target holds here and in
// every replica.
std::string target_gaps_section(const TargetGapInput& in);

}  // namespace needle
