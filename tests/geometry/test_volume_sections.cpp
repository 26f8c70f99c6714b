// Volume and cross-section properties against closed forms and quadrature done here.
#include <catch2/catch.hpp>
#include <cmath>

#include "geometry/cad_solid.h"
#include "geometry/exact_measures.h"
#include "geometry/section_properties.h"
#include "geometry/surface_measures.h"

using namespace needle;
namespace {
constexpr double kPi = 3.14159265358979323846;

// Simpson quadrature of f on [a, b].
template <class F>
double simpson(F f, double a, double b, int n = 20000) {
  const double h = (b - a) / n;
  double sum = f(a) + f(b);
  for (int i = 1; i < n; ++i) sum += (i % 2 ? 4 : 2) * f(a + i * h);
  return sum * h / 3;
}
}  // namespace

TEST_CASE("volume of a rod with one bevel equals pi R^2 (L - R cot theta)", "[geometry][volume]") {
  GrindingRecipe recipe;
  recipe.groove.reset();
  recipe.tip_y_mm = -0.5;
  recipe.grinds = {{"top", 23.5, 0, true, 0}};
  recipe.rod.length_mm = 10.0;
  const double R = 0.5, theta = 23.5 * kPi / 180;
  // The plane x = -(y + R) cot(theta) caps the rod; the mean of y over the disc is 0.
  const double closed_form = kPi * R * R * (10.0 - R / std::tan(theta));
  const TipGeometry tip = resolve_tip(recipe);
  CHECK(exact_volume_mm3(tip) == Approx(closed_form).epsilon(1e-5));
  const CadSolid solid = build_cad_solid(recipe);
  CHECK(std::abs(enclosed_volume_mm3(solid.surface) / closed_form - 1) < 0.005);
  CHECK(enclosed_volume_mm3(solid.surface) < closed_form);  // inscribed
}

TEST_CASE("preset volumes within 0.5 % of the smooth solid, half model is half", "[geometry][volume][slow]") {
  for (const std::string& name : preset_names()) {
    const CadSolid full = build_cad_solid(preset_recipe(name));
    const CadSolid half = build_cad_solid(preset_recipe(name), true);
    const double exact = exact_volume_mm3(full.tip);
    const double v_full = enclosed_volume_mm3(full.surface), v_half = enclosed_volume_mm3(half.surface);
    INFO(name << " mesh " << v_full << " exact " << exact);
    CHECK(std::abs(v_full / exact - 1) < 0.005);
    CHECK(v_half == Approx(0.5 * v_full).epsilon(1e-9));
  }
}

TEST_CASE("sections: plain rod and grooved section against closed forms", "[geometry][sections][slow]") {
  const CadSolid solid = build_cad_solid(preset_recipe("LMB"));
  const double R = 0.5, h = -0.07;
  const std::vector<SectionProperties> s = surface_sections(solid.surface, {-30.1, -10.1});
  // Behind the groove: a full circle.
  CHECK(std::abs(s[0].area_mm2 / (kPi * R * R) - 1) < 0.005);
  CHECK(std::abs(s[0].centroid_y_mm) < 1e-4);  // polygon edges are not spread symmetrically
  CHECK(std::abs(s[0].I_z_mm4 / (kPi * std::pow(R, 4) / 4) - 1) < 0.01);
  // In the groove: the circular segment y <= h.
  const double area = simpson([&](double y) { return 2 * std::sqrt(std::max(0.0, R * R - y * y)); }, -R, h);
  const double first = simpson([&](double y) { return y * 2 * std::sqrt(std::max(0.0, R * R - y * y)); }, -R, h);
  const double second = simpson([&](double y) { return y * y * 2 * std::sqrt(std::max(0.0, R * R - y * y)); }, -R, h);
  const double yc = first / area;
  const double Iz = second - area * yc * yc;
  // closed-form area of the segment as a cross-check of the quadrature
  CHECK(area == Approx(R * R * std::acos(-h / R) + h * std::sqrt(R * R - h * h)).epsilon(1e-6));
  CHECK(std::abs(s[1].area_mm2 / area - 1) < 0.005);
  CHECK(s[1].centroid_y_mm == Approx(yc).margin(2e-3));
  CHECK(std::abs(s[1].I_z_mm4 / Iz - 1) < 0.01);
  // The smooth solid's section agrees with the same quadrature to high accuracy.
  const SectionProperties e = exact_section(solid.tip, -10.1);
  CHECK(e.area_mm2 == Approx(area).epsilon(1e-6));
  CHECK(e.I_z_mm4 == Approx(Iz).epsilon(1e-5));
}

TEST_CASE("tip sections shrink toward A and agree with the smooth solid", "[geometry][sections][slow]") {
  for (const std::string& name : preset_names()) {
    const CadSolid solid = build_cad_solid(preset_recipe(name));
    std::vector<double> xs;
    for (double x = -0.1; x > -1.5; x -= 0.2) xs.push_back(x);
    const std::vector<SectionProperties> mesh = surface_sections(solid.surface, xs);
    for (size_t i = 0; i < xs.size(); ++i) {
      const SectionProperties exact = exact_section(solid.tip, xs[i]);
      INFO(name << " x " << xs[i]);
      CHECK(mesh[i].area_mm2 == Approx(exact.area_mm2).epsilon(0.01).margin(1e-4));
      if (i > 0) CHECK(exact.area_mm2 > exact_section(solid.tip, xs[i - 1]).area_mm2);
    }
  }
}
