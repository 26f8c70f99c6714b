#include "studies/calibration_steps.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

double next_calibration_E_MPa(const std::vector<CalibrationPoint>& runs, double target_mm) {
  NEEDLE_REQUIRE(!runs.empty(), "calibration: no run to step from");
  const CalibrationPoint& last = runs.back();
  double next;
  if (runs.size() == 1 || std::abs(last.deflection_mm - runs[runs.size() - 2].deflection_mm) < 1e-9) {
    NEEDLE_REQUIRE(last.deflection_mm * target_mm > 0,
                   fmt::format("at E = {:.4g} MPa the needle deflects {:+.3f} mm, the other way than the target {:+.3f} mm: "
                               "E alone cannot calibrate it",
                               last.E_MPa, last.deflection_mm, target_mm));
    next = last.E_MPa * target_mm / last.deflection_mm;
  } else {
    const CalibrationPoint& before = runs[runs.size() - 2];
    next = last.E_MPa + (target_mm - last.deflection_mm) / sensitivity_mm_per_MPa(last, before);
  }
  return std::clamp(next, last.E_MPa / 10, last.E_MPa * 10);
}

std::size_t nearest_to_target(const std::vector<CalibrationPoint>& runs, double target_mm) {
  NEEDLE_REQUIRE(!runs.empty(), "calibration: no runs");
  return static_cast<std::size_t>(std::min_element(runs.begin(), runs.end(), [&](const auto& a, const auto& b) {
                                    return std::abs(a.deflection_mm - target_mm) < std::abs(b.deflection_mm - target_mm);
                                  }) -
                                  runs.begin());
}

std::optional<std::size_t> nearest_in_E(const std::vector<CalibrationPoint>& runs, std::size_t best) {
  std::optional<std::size_t> nearest;
  auto distance = [&](std::size_t i) { return std::abs(std::log(runs[i].E_MPa / runs[best].E_MPa)); };
  for (std::size_t i = 0; i < runs.size(); ++i)
    if (runs[i].finished && runs[i].E_MPa != runs[best].E_MPa && (!nearest || distance(i) < distance(*nearest))) nearest = i;
  return nearest;
}

bool needs_sensitivity_run(const std::vector<CalibrationPoint>& runs, std::size_t best, double step) {
  const std::optional<std::size_t> nearest = nearest_in_E(runs, best);
  return !nearest || std::abs(runs[*nearest].E_MPa / runs[best].E_MPa - 1) > 2 * step;
}

double sensitivity_mm_per_MPa(const CalibrationPoint& a, const CalibrationPoint& b) {
  return (b.deflection_mm - a.deflection_mm) / (b.E_MPa - a.E_MPa);
}

}  // namespace needle
