// The strain probes (solver/insertion/strain_probes.h) against closed forms: the smallest principal Hencky strain of a
// rotated stretch, and the regions' membership and statistics on particles placed by hand.
#include <catch2/catch.hpp>
#include <cmath>

#include "solver/insertion/strain_probes.h"

using namespace needle;

TEST_CASE("Strain probes: the smallest principal Hencky strain of a rotated stretch is ln of its smallest stretch", "[solver][strain]") {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  for (const Eigen::Vector3d& stretch : {Eigen::Vector3d(1.3, 0.4, 0.9), Eigen::Vector3d(2.0, 1.5, 1.1), Eigen::Vector3d(0.3, 0.3, 3.0)}) {
    const Eigen::Matrix3d V = R * stretch.asDiagonal() * R.transpose();  // b = V^2 for a left stretch V
    CHECK(min_principal_log_strain(V * V) == Approx(std::log(stretch.minCoeff())).epsilon(1e-12));
  }
  CHECK(min_principal_log_strain(Eigen::Matrix3d::Identity()) == Approx(0.0).margin(1e-15));
  CHECK(std::isinf(min_principal_log_strain(Eigen::Matrix3d::Zero())));
}

TEST_CASE("Strain probes: each region takes its particles, and reports median, 5th percentile and minimum", "[solver][strain]") {
  StrainProbeInput in;
  in.tag_names = {"top", "lancet_pos", "bottom", "shaft", "groove_floor", "symmetry"};
  in.tip_point = Eigen::Vector3d(0, -0.1, 0);
  in.groove = GrooveBox{-0.07, -3.0, -25.0};
  in.radius_mm = 0.5;
  in.tissue_min_x_mm = -10, in.tissue_max_x_mm = 100;  // the groove's part in the tissue: x in [-10, -3]
  auto add = [&in](Eigen::Vector3d X, double strain, int tag) {
    in.reference_points.push_back(X);
    in.spacing_mm.push_back(0.2);
    in.min_principal_strain.push_back(strain);
    in.contact_tag.push_back(tag);
  };
  // Eleven particles on the top facets (tags 0 and 1): strains -1.0, -0.9, ..., 0.0.
  for (int k = 0; k <= 10; ++k) add({-0.5, 0.3, 0.1}, -1.0 + 0.1 * k, k % 2);
  // Below the tip: touching the bottom bevel and the rod's underside within 2 mm behind A, below A.
  add({-0.2, -0.3, 0.0}, -0.8, 2);
  add({-1.9, -0.5, 0.1}, -0.4, 3);
  // Not below the tip: too far behind A, above A, or ahead of A.
  add({-2.5, -0.5, 0.1}, -5.0, 3);
  add({-0.5, 0.0, 0.1}, -5.0, 2);
  add({0.3, -0.3, 0.1}, -5.0, 2);
  // In the groove's section: one touching the floor, one hanging in it untouched; one outside its width, one
  // beyond the tissue, one on the rod's top.
  add({-5.0, -0.05, 0.1}, -0.6, 4);
  add({-6.0, 0.3, 0.2}, -0.2, -1);
  add({-6.0, 0.3, 0.45}, -5.0, -1);  // |z| 0.45 > sqrt(0.25 - 0.09) = 0.4
  add({-12.0, 0.3, 0.1}, -5.0, -1);
  add({-6.0, 0.55, 0.1}, -5.0, -1);
  // Far from the needle (NaN) and a non-finite strain are left out.
  add({std::nan(""), 0, 0}, -5.0, 0);
  add({-0.5, 0.3, 0.1}, -std::numeric_limits<double>::infinity(), 0);

  const StrainProbes p = probe_strains(in);
  CHECK(p.tip_top.particles == 11);
  CHECK(p.tip_top.median == Approx(-0.5));
  CHECK(p.tip_top.p05 == Approx(-0.95));  // position 0.5 between -1.0 and -0.9
  CHECK(p.tip_top.min == Approx(-1.0));
  CHECK(p.below_tip.particles == 2);
  CHECK(p.below_tip.median == Approx(-0.6));
  CHECK(p.below_tip.min == Approx(-0.8));
  CHECK(p.groove.particles == 2);
  CHECK(p.groove.median == Approx(-0.4));
  CHECK(p.groove.min == Approx(-0.6));

  SECTION("an empty region reports no particles and NaN") {
    StrainProbeInput none = in;
    none.groove.reset();
    const StrainProbes q = probe_strains(none);
    CHECK(q.groove.particles == 0);
    CHECK(std::isnan(q.groove.median));
    CHECK(std::isnan(q.groove.p05));
  }
  SECTION("a contact tag outside the surface's tags is refused") {
    in.contact_tag.front() = 17;
    CHECK_THROWS(probe_strains(in));
  }
}
