#include "solver/insertion/tissue_sample.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/input_error.h"

namespace needle {

TissueSample measure_tissue_sample(const TissueSampleInput& in) {
  const size_t n = in.reference_points.size();
  NEEDLE_REQUIRE(in.spacing_mm.size() == n && in.volume_mm3.size() == n && in.mass_g.size() == n,
                 "tissue sample: one spacing, volume and mass per particle");
  NEEDLE_REQUIRE(in.touches_floor.empty() || in.touches_floor.size() == n, "tissue sample: one floor flag per particle, or none");
  NEEDLE_REQUIRE(in.bore_radius_mm > 0, "tissue sample: the bore's radius must be positive");
  TissueSample out;
  out.captured.assign(n, 0);
  double back = std::numeric_limits<double>::infinity(), front = -back, floor_back = back, floor_front = -back;
  std::vector<std::pair<double, double>> floor_spans;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& X = in.reference_points[i];
    const double h = in.spacing_mm[i];
    if (!X.allFinite() || X.x() < in.x_lo_mm || X.x() > in.x_hi_mm) continue;
    if (std::hypot(X.y(), X.z()) >= in.bore_radius_mm) continue;
    if (in.floor_y_mm && X.y() < *in.floor_y_mm - 0.5 * h) continue;
    out.captured[i] = 1;
    ++out.particles;
    out.volume_mm3 += in.volume_mm3[i];
    out.mass_g += in.mass_g[i];
    const double lo = std::max(in.x_lo_mm, X.x() - 0.5 * h), hi = std::min(in.x_hi_mm, X.x() + 0.5 * h);
    back = std::min(back, lo);
    front = std::max(front, hi);
    if (!in.touches_floor.empty() && in.touches_floor[i]) {
      ++out.floor_particles;
      floor_back = std::min(floor_back, lo);
      floor_front = std::max(floor_front, hi);
      floor_spans.emplace_back(lo, hi);
    }
  }
  if (out.particles > 0) {
    out.back_x_mm = back;
    out.front_x_mm = front;
    out.length_mm = front - back;
  }
  if (out.floor_particles > 0) {
    out.floor_length_mm = floor_front - floor_back;
    std::sort(floor_spans.begin(), floor_spans.end());
    double covered = 0, run_lo = floor_spans.front().first, run_hi = floor_spans.front().second;
    for (const auto& [lo, hi] : floor_spans) {
      if (lo > run_hi) {
        covered += run_hi - run_lo;
        run_lo = lo;
        run_hi = hi;
      } else {
        run_hi = std::max(run_hi, hi);
      }
    }
    out.floor_covered_mm = covered + (run_hi - run_lo);
  }
  return out;
}

}  // namespace needle
