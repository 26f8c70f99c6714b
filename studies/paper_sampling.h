#pragma once
// The paper report's sampling section (issue 50): the sample length I_s each needle's run predicts when its scene fires
// the cannula (summary.json "sample"), beside the paper's measured lengths, the ranking, each needle's ratio to SB, and
// the floor contact at the insertion's end beside the sample after the firing; and the two targets on them.
// The measured lengths are chicken breast's; the runs' tissue card is the report's to name.
#include <string>
#include <vector>

namespace needle {

struct SampledNeedle {
  std::string name;
  double I_s_mm, length_mm, volume_mm3;  // the run's sample (NaN: its scene did not fire the cannula)
  double floor_covered_mm;               // the length of the axis under the sample's floor-touching tissue (gaps left out)
  long floor_particles;                  // how many particles touch the floor (I_s is the extent between the outermost)
  double floor_layer_length_mm, floor_layer_covered_mm;  // the same two for the floor's nearest layer, by geometry
  double floor_contact_before;          // the groove's floor contact fraction at the insertion's end
  double measured_I_s_mm;               // the paper's (NaN: none)
};

struct SamplingVerdict {
  bool ranked = false;        // SB and LMB above AMB, AMB above HMB (predicted)
  bool ratios_within = false;  // every needle's I_s / I_s(SB) within kRatioTolerance of the measured ratio
  double worst_ratio_miss = 0;
  static constexpr double kRatioTolerance = 0.15;
};

// Needs SB, LMB, AMB and HMB among the needles, each with a sample; otherwise both false.
SamplingVerdict judge_sampling(const std::vector<SampledNeedle>& needles);

// The section's Markdown ("" when no needle has a sample); tissue: the runs' tissue card in words.
std::string sampling_section(const std::vector<SampledNeedle>& needles, const std::string& tissue);

}  // namespace needle
