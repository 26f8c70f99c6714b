#pragma once
// The driven motion of the needle's base plane (paper, Section II.D): constant acceleration from rest
// to the insertion speed over accel_time_ms, then constant speed until the travel is reached.
// Defaults: 0 -> 8 m/s (= mm/ms) in 0.75 ms (3 mm), then 8 m/s to 30 mm travel; 4.125 ms in all.
#include <string>

namespace needle {

struct InsertionProfile {
  double accel_time_ms = 0.75;
  double speed_mm_per_ms = 8.0;
  double travel_mm = 30.0;

  // InputError naming the field for non-positive values or a travel shorter than the ramp.
  void validate(const std::string& where = "motion") const;
  double end_time_ms() const;
  double velocity_mm_per_ms(double time_ms) const;  // the speed up to and at the end time, 0 after
  double displacement_mm(double time_ms) const;  // exact integral of the velocity
};

}  // namespace needle
