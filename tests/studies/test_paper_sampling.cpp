// The paper report's sampling section (studies/paper_sampling.h): its two targets judged on hand-made samples whose
// ratios to SB are known, and the section's table.
#include <catch2/catch.hpp>
#include <cmath>

#include "studies/paper_sampling.h"

using namespace needle;

namespace {

// The four needles with these predicted lengths and the paper's measured ones (12.5, 12.9, 9.9, 8.6 mm).
std::vector<SampledNeedle> needles(double sb, double lmb, double amb, double hmb) {
  return {{"SB", sb, sb, 1.0, sb, 50, sb, sb, 0.2, 12.5},
          {"LMB", lmb, lmb, 1.0, lmb, 50, lmb, lmb, 0.2, 12.9},
          {"AMB", amb, amb, 1.0, amb, 40, amb, amb, 0.1, 9.9},
          {"HMB", hmb, hmb, 1.0, hmb, 30, hmb, hmb, 0.0, 8.6}};
}

}  // namespace

TEST_CASE("The sampling targets: the ranking and each ratio to SB within 0.15 of the measured", "[studies][cannula]") {
  // The measured lengths themselves halved: ranked, every ratio exact.
  SamplingVerdict v = judge_sampling(needles(6.25, 6.45, 4.95, 4.3));
  CHECK(v.ranked);
  CHECK(v.ratios_within);
  CHECK(v.worst_ratio_miss == Approx(0).margin(1e-12));
  // HMB 0.2 of SB's length short of its measured ratio 0.688: ranked, its ratio missed by 0.2.
  v = judge_sampling(needles(10, 10.3, 7.9, 4.88));
  CHECK(v.ranked);
  CHECK_FALSE(v.ratios_within);
  CHECK(v.worst_ratio_miss == Approx(8.6 / 12.5 - 0.488).epsilon(1e-9));
  // Every groove filled alike (the whole groove each time): every ratio 1, AMB not above HMB.
  v = judge_sampling(needles(22, 22, 22, 22));
  CHECK_FALSE(v.ranked);
  CHECK(v.worst_ratio_miss == Approx(1 - 8.6 / 12.5).epsilon(1e-9));
  // A needle without a sample: no verdict.
  std::vector<SampledNeedle> three = needles(10, 10, 8, 7);
  three[3].I_s_mm = std::nan("");
  v = judge_sampling(three);
  CHECK_FALSE(v.ranked);
  CHECK_FALSE(v.ratios_within);
}

TEST_CASE("The sampling section tabulates each needle's sample and ratio, and is empty without a sample", "[studies][cannula]") {
  const std::string md = sampling_section(needles(12.5, 12.9, 9.9, 8.6), "PVC card, E 0.0855 MPa");
  CHECK(md.find("## The sample") != std::string::npos);
  CHECK(md.find("| AMB | 9.90 | 0.79 | 9.9 | 0.79 | 40 | 9.90 | 9.90 / 9.90 | 0.100 | 9.90 | 1.000 | 1.00 |") != std::string::npos);
  CHECK(md.find("Ranked by predicted I_s (longest first): LMB > SB > AMB > HMB") != std::string::npos);
  CHECK(md.find("PVC card, E 0.0855 MPa") != std::string::npos);
  std::vector<SampledNeedle> none = needles(1, 1, 1, 1);
  for (SampledNeedle& n : none) n.I_s_mm = std::nan("");
  CHECK(sampling_section(none, "").empty());
}
