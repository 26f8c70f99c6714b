#pragma once
// What the paper's report knows of a needle and the paper: the reference table
// (data/paper/reference.json), one needle's outcome (deflection, groove fill, status) and the paper's
// targets (issue 7) with their verdicts. Shared by the report (paper_report.h) and the comparison of
// models (model_comparison.h).
#include <limits>
#include <string>
#include <vector>

#include "plot/raster_image.h"

namespace needle {

struct PaperReferenceNeedle {
  std::string name;
  double d_a_mm = 0, deflection_experiment_mm = 0, deflection_lsdyna_mm = 0, sample_length_mm = 0;
  std::string groove_contact_in_model;
};

// The needles of the reference file in the paper's order (SB, LMB, AMB, HMB, then any other by name).
// InputError naming the file and key for a missing file, bad JSON or a missing number.
std::vector<PaperReferenceNeedle> read_paper_reference(const std::string& path);

// Whether the name is one of the paper's four needles.
bool is_paper_needle(const std::string& name);

// The named needle of the table, or null.
const PaperReferenceNeedle* find_reference(const std::vector<PaperReferenceNeedle>& reference, const std::string& name);

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One needle's end of insertion, from its run folder or from a report's results.json.
struct NeedleOutcome {
  std::string name, status;
  double deflection_mm = kNaN, insertion_mm = kNaN, groove_fill = kNaN;
  double sample_I_s_mm = kNaN, sample_contact_extent_mm = kNaN;  // a fired cannula's (runs/run_summary.h; NaN: none)
};

// The paper's targets (issue 7), each with its verdict and the numbers behind it.
struct PaperTarget {
  std::string what, numbers;
  bool met = false, checked = false;
  // A deflection target's needle, its error against the experiment (signed, mm) and the error allowed
  // (abs(error) <= allowed; HMB's: below LS-DYNA's); empty and NaN for the others.
  std::string needle = {};
  double error_mm = kNaN, allowed_mm = kNaN;
  std::string allowance = {};  // the allowance in words, e.g. "0.10 mm allowed"
};

// The named needle's outcome among runs, or null.
const NeedleOutcome* find_outcome(const std::vector<NeedleOutcome>& runs, const std::string& name);

std::vector<PaperTarget> evaluate_paper_targets(const std::vector<NeedleOutcome>& runs, const std::vector<PaperReferenceNeedle>& reference);

// A number in mm with its sign ("n/a" when not finite).
std::string fmt_mm(double v, const char* format = "{:+.3f}");

// The report's colours: this toolkit, the experiment, LS-DYNA.
inline const Rgb kOurs{31, 119, 180}, kExperiment{60, 60, 60}, kLsDyna{255, 127, 14};

// The colour of the k-th model set beside this report (k >= 1; k = 0 is this report, kOurs): never one
// of the three above, so a compared model is not mistaken for the experiment or LS-DYNA.
Rgb compared_model_colour(int k);

}  // namespace needle
