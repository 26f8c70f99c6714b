#include "solver/needle/insertion_profile.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <string>
#include <vector>

#include "core/input_error.h"

namespace needle {

std::string InsertionProfile::describe() const {
  const InsertionProfile paper;
  std::vector<std::string> parts;
  if (speed_mm_per_ms != paper.speed_mm_per_ms)
    parts.push_back(fmt::format("the needle is driven at {:g} m/s (the paper's model: {:g})", speed_mm_per_ms, paper.speed_mm_per_ms));
  if (decel_time_ms != paper.decel_time_ms) parts.push_back(fmt::format("the base decelerates to rest over {:g} ms", decel_time_ms));
  if (hold_ms != paper.hold_ms) parts.push_back(fmt::format("delta is read after the base is held still for {:g} ms", hold_ms));
  return fmt::format("{}", fmt::join(parts, "; "));
}

void InsertionProfile::validate(const std::string& where) const {
  NEEDLE_REQUIRE(std::isfinite(accel_time_ms) && accel_time_ms >= 0,
                 fmt::format("{}: accel_time_ms must be zero or positive (got {})", where, accel_time_ms));
  NEEDLE_REQUIRE(std::isfinite(speed_mm_per_ms) && speed_mm_per_ms > 0,
                 fmt::format("{}: the insertion speed must be positive (got {} m/s)", where, speed_mm_per_ms));
  NEEDLE_REQUIRE(speed_mm_per_ms <= kMaxSpeedMPerS,
                 fmt::format("{}: insertion speed {} m/s is beyond any biopsy device (at most {} m/s)", where, speed_mm_per_ms, kMaxSpeedMPerS));
  NEEDLE_REQUIRE(std::isfinite(travel_mm) && travel_mm > 0, fmt::format("{}: travel_mm must be positive (got {})", where, travel_mm));
  // No biopsy needle is longer than a metre: a travel beyond it is a typo (1e9 mm started a run of 1e11 steps).
  constexpr double kMaxTravelMm = 1000.0;
  NEEDLE_REQUIRE(travel_mm <= kMaxTravelMm, fmt::format("{}: travel {} mm is beyond any needle (at most {} mm)", where, travel_mm, kMaxTravelMm));
  NEEDLE_REQUIRE(std::isfinite(decel_time_ms) && decel_time_ms >= 0,
                 fmt::format("{}: decel_time_ms must be zero or positive (got {})", where, decel_time_ms));
  NEEDLE_REQUIRE(std::isfinite(hold_ms) && hold_ms >= 0, fmt::format("{}: hold_ms must be zero or positive (got {})", where, hold_ms));
  const double ramps_mm = 0.5 * speed_mm_per_ms * (accel_time_ms + decel_time_ms);
  NEEDLE_REQUIRE(travel_mm >= ramps_mm, fmt::format("{}: travel {} mm ends before the speed is reached ({} mm of ramps)", where,
                                                    travel_mm, ramps_mm));
}

double InsertionProfile::cruise_end_time_ms() const {
  return accel_time_ms + (travel_mm - 0.5 * speed_mm_per_ms * (accel_time_ms + decel_time_ms)) / speed_mm_per_ms;
}

double InsertionProfile::travel_end_time_ms() const { return cruise_end_time_ms() + decel_time_ms; }

double InsertionProfile::end_time_ms() const { return travel_end_time_ms() + hold_ms; }

double InsertionProfile::velocity_mm_per_ms(double t) const {
  const double stop = travel_end_time_ms();
  if (t <= 0 || t > stop) return 0.0;  // without a deceleration, still moving at the end of the travel
  if (t < accel_time_ms) return speed_mm_per_ms * t / accel_time_ms;
  if (t <= cruise_end_time_ms()) return speed_mm_per_ms;
  return speed_mm_per_ms * (stop - t) / decel_time_ms;
}

double InsertionProfile::displacement_mm(double t) const {
  t = std::clamp(t, 0.0, travel_end_time_ms());
  if (t < accel_time_ms) return 0.5 * speed_mm_per_ms * t * t / accel_time_ms;
  const double cruise_end = cruise_end_time_ms();
  const double at_cruise = 0.5 * speed_mm_per_ms * accel_time_ms + speed_mm_per_ms * (std::min(t, cruise_end) - accel_time_ms);
  if (t <= cruise_end) return at_cruise;
  const double s = t - cruise_end;  // into the deceleration
  return at_cruise + speed_mm_per_ms * s - 0.5 * speed_mm_per_ms * s * s / decel_time_ms;
}

}  // namespace needle
