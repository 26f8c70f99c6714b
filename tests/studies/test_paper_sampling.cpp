// The paper report's sampling section (studies/paper_sampling.h): its two targets judged on hand-made samples whose
// ratios to SB are known, and the section's table.
#include <catch2/catch.hpp>
#include <cmath>

#include "studies/paper_sampling.h"

using namespace needle;

namespace {

// The four needles with these predicted lengths (I_s, and the contact's extent the same unless given) and the paper's
// measured ones (12.5, 12.9, 9.9, 8.6 mm).
std::vector<SampledNeedle> needles(double sb, double lmb, double amb, double hmb) {
  return {{"SB", sb, 50, sb, 5, 22, 1.0, 0.2, 12.5},
          {"LMB", lmb, 50, lmb, 5, 22, 1.0, 0.2, 12.9},
          {"AMB", amb, 40, amb, 4, 22, 1.0, 0.1, 9.9},
          {"HMB", hmb, 30, hmb, 3, 22, 1.0, 0.0, 8.6}};
}

// A replica: only names and the two lengths, no measured lengths (the report's are used).
SampledReplica replica(const std::string& label, std::vector<SampledNeedle> n, std::vector<double> contact_extent) {
  for (size_t k = 0; k < n.size(); ++k) {
    n[k].contact_extent_mm = contact_extent[k];
    n[k].measured_I_s_mm = std::nan("");
  }
  return {label, n};
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

TEST_CASE("The sampling targets are judged on the length asked for: I_s, or the contact's extent beside it", "[studies][cannula]") {
  // I_s the measured lengths halved; the contact's extent the whole groove for all but HMB (4 mm): I_s meets both
  // targets, the extent neither (SB and LMB not above AMB; HMB's ratio 0.18 against 0.69).
  std::vector<SampledNeedle> n = needles(6.25, 6.45, 4.95, 4.3);
  for (SampledNeedle& x : n) x.contact_extent_mm = x.name == "HMB" ? 4.0 : 22.0;
  CHECK(judge_sampling(n).met());
  const SamplingVerdict extent = judge_sampling(n, &SampledNeedle::contact_extent_mm);
  CHECK_FALSE(extent.ranked);
  CHECK_FALSE(extent.ratios_within);
  CHECK(extent.worst_ratio_miss == Approx(std::abs(4.0 / 22 - 8.6 / 12.5)).epsilon(1e-9));
}

TEST_CASE("Each lattice is judged with the report's measured lengths, and a replica without all four needles is left out", "[studies][cannula]") {
  const std::vector<SampledNeedle> report = needles(12.5, 12.9, 9.9, 8.6);
  // Replica a: I_s doubled (same ratios: met), its contact extent HMB 0.2 short of the measured ratio; replica b: HMB's I_s
  // above AMB's but its ratio (0.80) within 0.15 of the measured; replica c: no HMB.
  const SampledReplica a = replica("a", needles(25, 25.8, 19.8, 17.2), {25, 25.8, 19.8, 25 * (8.6 / 12.5 - 0.2)});
  const SampledReplica b = replica("b", needles(12.5, 12.9, 9.9, 10.0), {12.5, 12.9, 9.9, 10.0});
  SampledReplica c = replica("c", needles(12.5, 12.9, 9.9, 8.6), {12.5, 12.9, 9.9, 8.6});
  c.needles.pop_back();
  const std::vector<SamplingLattice> l = judge_sampling_lattices(report, {a, b, c});
  REQUIRE(l.size() == 3);
  CHECK(l[0].label == "this report");
  CHECK(l[0].I_s.met());
  CHECK(l[1].label == "a");
  CHECK(l[1].I_s.met());
  CHECK(l[1].I_s.worst_ratio_miss == Approx(0).margin(1e-12));
  CHECK(l[1].contact_extent.ranked);
  CHECK_FALSE(l[1].contact_extent.ratios_within);
  CHECK(l[1].contact_extent.worst_ratio_miss == Approx(0.2).epsilon(1e-9));
  CHECK(l[2].label == "b");
  CHECK_FALSE(l[2].I_s.ranked);
  CHECK(l[2].I_s.ratios_within);
  CHECK(l[2].I_s.worst_ratio_miss == Approx(10.0 / 12.5 - 8.6 / 12.5).epsilon(1e-9));
}

TEST_CASE("The sampling section tabulates each needle's sample and ratio and each lattice's verdicts, and is empty without a sample", "[studies][cannula]") {
  const std::vector<SampledNeedle> report = needles(12.5, 12.9, 9.9, 8.6);
  const std::string md = sampling_section(report, "PVC card, E 0.0855 MPa");
  CHECK(md.find("## The sample") != std::string::npos);
  CHECK(md.find("| AMB | 9.90 | 0.79 | 9.9 | 0.79 | 40 | 9.90, 0.79 [4] | 22.00 | 1.000, 1.00 | 0.100 |") != std::string::npos);
  CHECK(md.find("Ranked by predicted I_s (longest first): LMB > SB > AMB > HMB") != std::string::npos);
  CHECK(md.find("PVC card, E 0.0855 MPa") != std::string::npos);
  CHECK(md.find("| SB and LMB above AMB, AMB above HMB | met |\n") != std::string::npos);
  CHECK(md.find("| lattice |") == std::string::npos);  // no replica, no lattice table
  // With one replica that misses the ranking: 1 of 2, and its row.
  const std::string with_replica = sampling_section(report, "", {replica("x + 0.1 mm", needles(12.5, 12.9, 9.9, 10.0), {22, 22, 22, 22})});
  CHECK(with_replica.find("| target (judged on I_s) | this report | every lattice (this report and 1 replica) |") != std::string::npos);
  CHECK(with_replica.find("| SB and LMB above AMB, AMB above HMB | met | 1 of 2 |") != std::string::npos);
  CHECK(with_replica.find("| x + 0.1 mm | 12.50 | 1.03, 0.79, 0.80 | **not ranked**, ratios within (worst 0.11) | 1.00, 1.00, 1.00 | "
                          "**not ranked**, **ratios missed** (worst 0.31) |") != std::string::npos);
  std::vector<SampledNeedle> none = needles(1, 1, 1, 1);
  for (SampledNeedle& n : none) n.I_s_mm = std::nan("");
  CHECK(sampling_section(none, "").empty());
}
