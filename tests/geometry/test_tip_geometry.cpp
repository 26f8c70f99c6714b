// Tip point, d_a and the recipe checks, against plane intersections solved here independently.
#include <catch2/catch.hpp>
#include <Eigen/Dense>
#include <cmath>

#include "geometry/cad_solid.h"
#include "core/input_error.h"
#include "geometry/surface_measures.h"

using namespace needle;
namespace {
constexpr double kPi = 3.14159265358979323846;

Eigen::Vector3d normal_of(double tilt_deg, double rot_deg) {
  const double t = tilt_deg * kPi / 180, r = rot_deg * kPi / 180;
  return {std::sin(t), std::cos(t) * std::cos(r), std::cos(t) * std::sin(r)};
}

// Intersection of the top, bottom and side_pos planes, each through its reported point.
Eigen::Vector3d three_plane_point(const TipGeometry& tip) {
  Eigen::Matrix3d M;
  Eigen::Vector3d rhs;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d n = normal_of(tip.facets[i].tilt_deg, tip.facets[i].rotation_deg);
    M.row(i) = n.transpose();
    rhs(i) = n.dot(tip.facets[i].point);
  }
  return M.fullPivLu().solve(rhs);
}
}  // namespace

TEST_CASE("paper presets have the paper's d_a and tip point on the axis plane", "[geometry]") {
  const std::vector<std::pair<std::string, double>> expected = {{"SB", -0.43}, {"LMB", -0.22}, {"AMB", 0.0}, {"HMB", 0.37}};
  for (const auto& [name, d_a] : expected) {
    const TipGeometry tip = resolve_tip(preset_recipe(name));
    REQUIRE(tip.d_a_mm().has_value());
    CHECK(*tip.d_a_mm() == Approx(d_a).margin(1e-12));
    CHECK(tip.groove->floor_y_mm == Approx(-0.07).margin(1e-12));
    CHECK(tip.tip_point.x() == 0.0);
    CHECK(tip.tip_point.z() == 0.0);
  }
}

TEST_CASE("facet normals follow the SPEC convention", "[geometry]") {
  const TipGeometry tip = resolve_tip(preset_recipe("LMB"));
  for (const FacetPlane& f : tip.facets) CHECK((f.normal - normal_of(f.tilt_deg, f.rotation_deg)).norm() < 1e-15);
  CHECK(tip.facets[0].normal.y() > 0);  // top faces the groove side
  CHECK(tip.facets[1].normal.y() < 0);  // bottom faces away
  CHECK(tip.facets[2].normal.z() > 0);  // side_pos faces +z
}

TEST_CASE("the solid's most distal vertex is the analytic plane intersection to 1e-9 mm", "[geometry][slow]") {
  for (double d_a : {-0.22, 0.0, 0.37, -0.4, 0.2, 0.48}) {
    for (bool half : {false, true}) {
      const CadSolid solid = build_cad_solid(multi_bevel_recipe(d_a), half);
      const Eigen::Vector3d analytic = three_plane_point(solid.tip);
      const Eigen::Vector3d mesh_tip = most_distal_point(solid.surface);
      INFO("d_a " << d_a << " half " << half);
      CHECK((mesh_tip - analytic).norm() < 1e-9);
      CHECK(mesh_tip.y() - solid.tip.groove->floor_y_mm == Approx(d_a).margin(1e-9));
    }
  }
  // SB: A is where the top plane meets the rod's bottom line (y = -R, z = 0).
  const CadSolid sb = build_cad_solid(preset_recipe("SB"));
  const Eigen::Vector3d n = normal_of(23.5, 0);
  const double x_on_bottom = (n.dot(sb.tip.facets[0].point) - n.y() * -0.5) / n.x();
  CHECK((most_distal_point(sb.surface) - Eigen::Vector3d(x_on_bottom, -0.5, 0)).norm() < 1e-9);
}

TEST_CASE("custom angles still converge at A", "[geometry][slow]") {
  MultiBevelAngles angles;
  angles.top_tilt_deg = 30;
  angles.bevel_tilt_deg = 15;
  angles.side_rotation_deg = 95;
  const CadSolid solid = build_cad_solid(multi_bevel_recipe(-0.1, angles));
  CHECK((most_distal_point(solid.surface) - three_plane_point(solid.tip)).norm() < 1e-9);
}

TEST_CASE("bad recipes fail with one clear message", "[geometry][errors]") {
  CHECK_THROWS_AS(preset_recipe("XYZ"), InputError);
  CHECK_THROWS_WITH(resolve_tip(multi_bevel_recipe(-0.5)), Catch::Contains("outside the rod"));
  CHECK_THROWS_WITH(resolve_tip(multi_bevel_recipe(0.6)), Catch::Contains("outside the rod"));
  Groove deep;
  deep.remaining_thickness_mm = -0.1;
  CHECK_THROWS_WITH(resolve_tip(multi_bevel_recipe(0.0, {}, {}, deep)), Catch::Contains("deeper than the rod"));
  Rod no_rod;
  no_rod.length_mm = 0.0;
  CHECK_THROWS_WITH(resolve_tip(multi_bevel_recipe(0.0, {}, no_rod)), Catch::Contains("rod length must be positive"));
  Groove zero_length;
  zero_length.length_mm = 0.0;
  CHECK_THROWS_WITH(resolve_tip(multi_bevel_recipe(0.0, {}, {}, zero_length)), Catch::Contains("groove length"));

  // Facets that leave a gap around A: the rod runs on past A.
  GrindingRecipe open;
  open.tip_y_mm = 0.0;
  open.grinds = {{"top", 20, 0, true, 0}, {"side", 20, 90, true, 0}};
  CHECK_THROWS_WITH(resolve_tip(open), Catch::Contains("cannot converge"));

  // Two grinds whose edge is perpendicular to the axis: a chisel, not a point.
  GrindingRecipe chisel;
  chisel.grinds = {{"upper", 20, 0, false, 0.5}, {"lower", 20, 180, false, 0.5}};
  CHECK_THROWS_WITH(resolve_tip(chisel), Catch::Contains("blunt"));

  GrindingRecipe flat = preset_recipe("SB");
  flat.grinds[0].tilt_deg = 0.0;
  CHECK_THROWS_WITH(resolve_tip(flat), Catch::Contains("tilt must be in (0, 90)"));
}
