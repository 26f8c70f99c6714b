#pragma once
// The arithmetic of `needle calibrate`, apart from the runs it makes: the next E toward a target
// deflection, the run nearest the target, and the local slope d delta / d E from two runs.
#include <cstddef>
#include <optional>
#include <vector>

namespace needle {

struct CalibrationPoint {
  double E_MPa = 0, deflection_mm = 0;
  bool finished = true;  // a run that stopped early gives no slope
};

// The next E to run: proportional (delta ~ E) after the first run or when the last two runs agree,
// a secant step on the last two otherwise; never more than a decade from the last E. Throws
// InputError when the only run deflects the other way than the target.
double next_calibration_E_MPa(const std::vector<CalibrationPoint>& runs, double target_mm);

// Index of the run whose deflection lies nearest the target (runs must not be empty).
std::size_t nearest_to_target(const std::vector<CalibrationPoint>& runs, double target_mm);

// Index of the finished run nearest in log E to runs[best], other than best's E; none if there is none.
std::optional<std::size_t> nearest_in_E(const std::vector<CalibrationPoint>& runs, std::size_t best);

// Whether one more run is needed to measure the slope at runs[best]: no finished run lies within a
// relative distance of 2 step in E.
bool needs_sensitivity_run(const std::vector<CalibrationPoint>& runs, std::size_t best, double step);

// d delta / d E (mm per MPa) between two runs.
double sensitivity_mm_per_MPa(const CalibrationPoint& a, const CalibrationPoint& b);

}  // namespace needle
