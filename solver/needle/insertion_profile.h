#pragma once
// The driven motion of the needle's base plane (paper, Section II.D): constant acceleration from rest
// to the insertion speed over accel_time_ms, then constant speed, then (decel_time_ms > 0) constant
// deceleration to rest exactly at the travel; then, if hold_ms > 0, the base is held still there (the
// experiment measures the tip at rest). A stop with no deceleration is instantaneous: the steel, undamped,
// then rings axially with the kinetic energy it had.
// Defaults: 0 -> 8 m/s (= mm/ms) in 0.75 ms (3 mm), then 8 m/s to 30 mm travel; 4.125 ms in all; the
// paper's model ends at full speed (no deceleration, no hold).
#include <string>

namespace needle {

struct InsertionProfile {
  // A biopsy gun fires at a few m/s (the paper's drive 8 m/s): beyond this a speed is a typo (validate, the scene reader).
  static constexpr double kMaxSpeedMPerS = 100.0;
  double accel_time_ms = 0.75;
  double speed_mm_per_ms = 8.0;
  double travel_mm = 30.0;
  double decel_time_ms = 0.0;  // the ramp from the speed to rest at the travel's end
  double hold_ms = 0.0;        // the base held still after the travel

  // InputError naming the field for non-positive values or a travel shorter than the two ramps.
  void validate(const std::string& where = "motion") const;
  // The drive in a run's one-line description (the paper report): its speed, a stop or a hold where they are not the
  // paper's model's (8 m/s, read at full speed), "; " between them; empty for the paper's.
  std::string describe() const;
  double cruise_end_time_ms() const;  // when the deceleration starts (the travel's end without one)
  double travel_end_time_ms() const;  // when the travel is reached
  double end_time_ms() const;  // the travel's end plus the hold
  double velocity_mm_per_ms(double time_ms) const;  // the speed up to and at the travel's end, 0 after
  double displacement_mm(double time_ms) const;  // exact integral of the velocity
};

}  // namespace needle
