// Facet areas of the tessellated solid against the exact areas of the smooth solid, and the exact
// areas themselves against closed forms.
#include <catch2/catch.hpp>
#include <cmath>
#include <array>
#include <random>

#include "geometry/cad_solid.h"
#include "geometry/exact_measures.h"
#include "core/input_error.h"
#include "geometry/surface_measures.h"

using namespace needle;
namespace {
constexpr double kPi = 3.14159265358979323846;

void check_facet_areas(const GrindingRecipe& recipe, bool half, double rel_tol) {
  const CadSolid solid = build_cad_solid(recipe, half);
  const std::vector<double> areas = area_by_tag_mm2(solid.surface);
  ExactOptions exact;
  exact.half_model = half;
  for (size_t i = 0; i < solid.tip.facets.size(); ++i) {
    const std::string& name = solid.tip.facets[i].name;
    const int tag = solid.surface.tag_index(name);
    const double mesh_area = tag >= 0 ? areas[tag] : 0.0;
    const double exact_area = exact_facet_area_mm2(solid.tip, static_cast<int>(i), exact);
    INFO(recipe.name << (half ? " half" : " full") << " facet " << name << ": mesh " << mesh_area << " exact " << exact_area);
    if (exact_area < 1e-4) {
      CHECK(mesh_area == Approx(exact_area).margin(1e-6));
    } else {
      CHECK(std::abs(mesh_area / exact_area - 1.0) < rel_tol);
    }
  }
}
}  // namespace

TEST_CASE("SB top facet equals the closed form pi R^2 / sin(theta)", "[geometry][areas]") {
  for (double tilt : {23.5, 15.0, 40.0}) {
    GrindingRecipe recipe;
    recipe.groove.reset();
    recipe.tip_y_mm = -0.5;
    recipe.grinds = {{"top", tilt, 0, true, 0}};
    const double closed_form = kPi * 0.25 / std::sin(tilt * kPi / 180);
    const TipGeometry tip = resolve_tip(recipe);
    CHECK(exact_facet_area_mm2(tip, 0) == Approx(closed_form).epsilon(1e-7));
    const CadSolid solid = build_cad_solid(recipe);
    const double mesh_area = area_by_tag_mm2(solid.surface)[solid.surface.tag_index("top")];
    CHECK(std::abs(mesh_area / closed_form - 1) < 0.005);
    // The mesh is inscribed in the cylinder: its area never exceeds the smooth one.
    CHECK(mesh_area <= closed_form);
  }
}

TEST_CASE("preset facet areas within 0.5 % of the smooth solid, full and half", "[geometry][areas][slow]") {
  for (const std::string& name : preset_names())
    for (bool half : {false, true}) check_facet_areas(preset_recipe(name), half, 0.005);
}

TEST_CASE("arbitrary multi-bevel tips: facet areas within 0.5 %", "[geometry][areas][slow]") {
  std::mt19937 random(20261122);
  std::uniform_real_distribution<double> d_a(-0.42, 0.5), top(15, 35), bevel(8, 20), side(90, 135);
  for (int trial = 0; trial < 6; ++trial) {
    MultiBevelAngles angles{top(random), bevel(random), side(random)};
    GrindingRecipe recipe = multi_bevel_recipe(d_a(random), angles);
    check_facet_areas(recipe, false, 0.005);
  }
  // d_a in (-0.5, -0.43) puts A below the rod: refused, not silently moved.
  CHECK_THROWS_AS(build_cad_solid(multi_bevel_recipe(-0.46)), InputError);
}

TEST_CASE("groove floor and walls match their closed forms", "[geometry][areas][slow]") {
  const CadSolid solid = build_cad_solid(preset_recipe("LMB"));
  const std::vector<double> areas = area_by_tag_mm2(solid.surface);
  const double R = 0.5, h = -0.07, length = 22.0;
  const double half_width = std::sqrt(R * R - h * h);
  CHECK(areas[solid.surface.tag_index("groove_floor")] == Approx(length * 2 * half_width).epsilon(1e-9));
  // Each wall is the circular segment above the floor: R^2 acos(h/R) - h sqrt(R^2 - h^2).
  const double segment = R * R * std::acos(h / R) - h * half_width;
  CHECK(std::abs(areas[solid.surface.tag_index("groove_wall")] / (2 * segment) - 1) < 0.005);
  // The base is a full disc.
  CHECK(std::abs(areas[solid.surface.tag_index("base")] / (kPi * R * R) - 1) < 0.005);
}

TEST_CASE("every triangle is tagged and the solid is a closed manifold", "[geometry][slow]") {
  for (const std::string& name : preset_names())
    for (bool half : {false, true}) {
      const CadSolid solid = build_cad_solid(preset_recipe(name), half);
      CHECK(check_topology(solid.surface).closed_manifold());
      CHECK(solid.surface.face_tag.size() == solid.surface.num_faces());
      CHECK(solid.surface.face_tag.minCoeff() >= 0);
      CHECK((solid.surface.tag_index("symmetry") >= 0) == half);
      if (half) {
        CHECK(solid.surface.V.col(2).minCoeff() >= 0.0);
        // The symmetry face is the solid's z = 0 section: the strip |y| <= R behind the facets'
        // traces, minus the groove's rectangle. Clip the strip here with the traces.
        std::vector<std::array<double, 2>> poly = {{solid.tip.base_x_mm, -0.5}, {1.0, -0.5}, {1.0, 0.5}, {solid.tip.base_x_mm, 0.5}};
        for (const FacetPlane& f : solid.tip.facets) {
          std::vector<std::array<double, 2>> out;
          auto g = [&](const std::array<double, 2>& p) {
            return f.normal.x() * (p[0] - f.point.x()) + f.normal.y() * (p[1] - f.point.y()) - f.normal.z() * f.point.z();
          };
          for (size_t k = 0; k < poly.size(); ++k) {
            const auto& p = poly[k];
            const auto& q = poly[(k + 1) % poly.size()];
            if (g(p) <= 0) out.push_back(p);
            if ((g(p) < 0) != (g(q) < 0) && g(p) != 0 && g(q) != 0) {
              const double t = g(p) / (g(p) - g(q));
              out.push_back({p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])});
            }
          }
          poly = out;
        }
        double twice = 0;
        for (size_t k = 0; k < poly.size(); ++k)
          twice += poly[k][0] * poly[(k + 1) % poly.size()][1] - poly[(k + 1) % poly.size()][0] * poly[k][1];
        const GrooveBox& g = *solid.tip.groove;
        const double expected = 0.5 * std::abs(twice) - (g.front_x_mm - g.back_x_mm) * (0.5 - g.floor_y_mm);
        const double sym = area_by_tag_mm2(solid.surface)[solid.surface.tag_index("symmetry")];
        CHECK(sym == Approx(expected).epsilon(1e-9));
      }
    }
}

TEST_CASE("chord tolerance trades triangles for accuracy", "[geometry][areas][slow]") {
  GrindingRecipe coarse = preset_recipe("HMB"), fine = preset_recipe("HMB");
  coarse.tessellation.chord_tolerance_mm = 4e-3;
  coarse.tessellation.min_segments_per_arc = 4;
  fine.tessellation.chord_tolerance_mm = 2.5e-4;
  const CadSolid a = build_cad_solid(coarse), b = build_cad_solid(fine);
  CHECK(a.surface.num_faces() < b.surface.num_faces());
  const double exact = exact_facet_area_mm2(a.tip, 1);
  const int tag = a.surface.tag_index("bottom");
  const double err_coarse = std::abs(area_by_tag_mm2(a.surface)[tag] / exact - 1);
  const double err_fine = std::abs(area_by_tag_mm2(b.surface)[tag] / exact - 1);
  CHECK(err_fine < err_coarse);
}
