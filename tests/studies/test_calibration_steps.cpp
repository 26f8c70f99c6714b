// The calibration arithmetic of `needle calibrate` on a closed-form deflection law: the steps reach
// the target, the slope from the sensitivity run matches the law's derivative, and the rules for
// when to make that run hold.
#include <catch2/catch.hpp>
#include <cmath>

#include "studies/calibration_steps.h"
#include "core/input_error.h"

using namespace needle;

namespace {
// A power law like the insertion's: delta = -c E^p, with delta(0.075) = -1.14 mm.
constexpr double kExponent = 0.6;
double law_deflection_mm(double E_MPa) { return -1.14 * std::pow(E_MPa / 0.075, kExponent); }
}  // namespace

TEST_CASE("calibration steps reach the target of a power law and measure its slope") {
  const double target = -1.14, tolerance = 0.05, step = 0.2;
  std::vector<CalibrationPoint> runs{{0.665, law_deflection_mm(0.665)}};
  while (std::abs(runs.back().deflection_mm - target) > tolerance) {
    REQUIRE(runs.size() < 6);
    const double E = next_calibration_E_MPa(runs, target);
    runs.push_back({E, law_deflection_mm(E)});
  }
  std::size_t best = nearest_to_target(runs, target);
  CHECK(best == runs.size() - 1);
  CHECK(std::abs(runs[best].E_MPa / 0.075 - 1) < 0.1);  // tolerance 0.05 of 1.14 is 4.4 % of delta, 7 % of E

  // A sensitivity run is needed exactly when no other run lies within 2 steps of the best E.
  bool close_run = false;
  for (std::size_t i = 0; i < runs.size(); ++i)
    close_run |= i != best && std::abs(runs[i].E_MPa / runs[best].E_MPa - 1) <= 2 * step;
  CHECK(needs_sensitivity_run(runs, best, step) == !close_run);

  // The best run alone needs one; with it the slope is the law's forward difference.
  runs = {runs[best]};
  best = 0;
  REQUIRE(needs_sensitivity_run(runs, best, step));
  runs.push_back({runs[best].E_MPa * (1 + step), law_deflection_mm(runs[best].E_MPa * (1 + step))});
  CHECK_FALSE(needs_sensitivity_run(runs, best, step));
  const auto partner = nearest_in_E(runs, best);
  REQUIRE(partner);
  CHECK(*partner == 1);
  const double relative = sensitivity_mm_per_MPa(runs[best], runs[*partner]) * runs[best].E_MPa / runs[best].deflection_mm;
  CHECK(relative == Approx((std::pow(1 + step, kExponent) - 1) / step).epsilon(1e-9));
  CHECK(std::abs(relative - kExponent) < 0.05 * kExponent);
}

TEST_CASE("calibration steps: stopped runs give no slope, steps are at most a decade, the wrong sign is refused") {
  std::vector<CalibrationPoint> runs{{0.1, -1.0}, {0.12, -1.1, false}};
  CHECK(nearest_in_E(runs, 0) == std::nullopt);
  CHECK(needs_sensitivity_run(runs, 0, 0.2));
  runs.push_back({0.09, -0.95});
  CHECK(nearest_in_E(runs, 0) == std::size_t{2});
  CHECK_FALSE(needs_sensitivity_run(runs, 0, 0.2));  // 10 % away, within 2 x 20 %
  CHECK(needs_sensitivity_run(runs, 0, 0.04));       // but not within 2 x 4 %

  // A secant through two nearly equal deflections would leap; the step is clamped to a decade.
  std::vector<CalibrationPoint> flat{{1.0, -0.10}, {1.1, -0.1001}};
  CHECK(next_calibration_E_MPa(flat, -1.14) == Approx(11.0));
  // One run deflecting the other way: E alone cannot get there.
  CHECK_THROWS_AS(next_calibration_E_MPa({{0.1, +0.3}}, -1.14), InputError);
}
