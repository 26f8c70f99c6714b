#pragma once
// The paper's report (`needle paper`): from the run folders of the four needles and the paper's
// reference table (data/paper/reference.json) it writes, into the report folder,
//   report.md                    the table of our deflection beside the experiment and LS-DYNA, the
//                                paper's targets with pass/fail and the numbers, the groove ranking;
//   results.json                 per needle: deflection_mm, groove_fill, runtime_s and the rest;
//   deflection_vs_insertion.png  delta against insertion length, all needles, the experiment's end values;
//   deflection_bars.png          delta of ours, the experiment and LS-DYNA per needle;
//   groove_fill.png              groove fill per needle beside the measured sample lengths;
//   facet_forces.png             the y force on each tip facet against insertion, one panel per needle;
//   tips.png                     the four tips, from above and below;
//   models.png                   with compared models: delta of each model, the experiment and LS-DYNA.
// With replicas the report and results.json also give each deflection's run-to-run scatter and the targets
// in the replicas.
// Every file is written whole or not at all.
#include <string>
#include <vector>

#include "studies/model_comparison.h"
#include "studies/paper_results.h"
#include "studies/run_replicas.h"

namespace needle {

struct PaperReportInput {
  std::string out_dir;                     // the report folder; run folders are out_dir/runs/NAME
  std::vector<std::string> needles;        // in the order to show
  std::vector<PaperReferenceNeedle> reference;
  std::string reference_path;
  double tissue_E_MPa = 0;
  std::string tissue_E_source;             // how E was chosen (calibration file, flag or default)
  std::string calibration_path;            // calibration.json of `needle calibrate`, if E came from one
  // The record of a parameter besides E fitted to a needle (data/paper/crushed_depth_hmb.json, written by
  // studies/sensitivity/second_parameter.py --record): where the fitted needle's run uses its value, the report names the
  // parameter as fitted and gives its leave-one-needle-out errors. Empty or another value in the runs: no such section.
  std::string fitted_path;
  std::string command_line;                // to regenerate
  bool draw_tips = true;
  std::vector<ComparedModel> compare;      // other models' results.json, in the order to show
  std::vector<ComparedModel> replicas;     // this model's runs repeated with a numerical detail changed (apps/run_replicas.h)
  std::string label = "this report";       // this report's model among them
};

// InputError if a needle's run folder or its summary is missing, or a compared results.json cannot be read.
void write_paper_report(const PaperReportInput& input);

}  // namespace needle
