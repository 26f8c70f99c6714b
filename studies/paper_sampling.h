#pragma once
// The paper report's sampling section (issue 50): the sample length I_s each needle's run predicts when its scene fires
// the cannula (summary.json "sample"), beside the paper's measured lengths, the ranking, each needle's ratio to SB, and
// the floor contact at the insertion's end beside the sample after the firing; the two targets judged on I_s in
// this report and in each replica (the same model, the particle lattice shifted), and, beside them, on the contact's
// extent, the first reading of I_s. The measured lengths are chicken breast's; the runs' tissue card is the
// report's to name.
#include <string>
#include <vector>

namespace needle {

struct SampledNeedle {
  std::string name;
  double I_s_mm;                 // the length of groove floor the sample rests on (NaN: its scene did not fire the cannula)
  long floor_layer_particles;    // how many of the sample's particles rest on the floor (the floor's nearest layer)
  double contact_extent_mm;      // the extent of the sample the contact lists on the floor when the cannula stops
  long contact_particles;        // how many it lists
  double length_mm, volume_mm3;  // the whole sample's extent along the axis and its volume
  double floor_contact_before;   // the groove's floor contact fraction at the insertion's end
  double measured_I_s_mm;        // the paper's (NaN: none)
};

struct SamplingVerdict {
  bool ranked = false;         // SB and LMB above AMB, AMB above HMB (predicted)
  bool ratios_within = false;  // every needle's length / SB's within kRatioTolerance of the measured ratio
  double worst_ratio_miss = 0;
  bool met() const { return ranked && ratios_within; }
  static constexpr double kRatioTolerance = 0.15;
};

// Judged on `length` (I_s by default). Needs SB, LMB, AMB and HMB among the needles, each with that length and a
// measured I_s; otherwise both false.
SamplingVerdict judge_sampling(const std::vector<SampledNeedle>& needles, double SampledNeedle::*length = &SampledNeedle::I_s_mm);

// A replica's samples: only name, I_s_mm and contact_extent_mm are read (the measured lengths are this report's).
struct SampledReplica {
  std::string label;
  std::vector<SampledNeedle> needles;
};

// The two verdicts of each lattice: this report's first, then each replica with samples of all four needles.
struct SamplingLattice {
  std::string label;
  std::vector<SampledNeedle> needles;  // with this report's measured lengths
  SamplingVerdict I_s, contact_extent;
};
std::vector<SamplingLattice> judge_sampling_lattices(const std::vector<SampledNeedle>& needles, const std::vector<SampledReplica>& replicas);

// The section's Markdown ("" when no needle has a sample); tissue: the runs' tissue card in words.
std::string sampling_section(const std::vector<SampledNeedle>& needles, const std::string& tissue,
                             const std::vector<SampledReplica>& replicas = {});

}  // namespace needle
