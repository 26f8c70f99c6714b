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
  out.in_floor_layer.assign(n, 0);
  double back = std::numeric_limits<double>::infinity(), front = -back;
  std::vector<std::pair<double, double>> floor_spans, layer_spans;  // each floor particle's interval along x
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
    if (!in.touches_floor.empty() && in.touches_floor[i]) floor_spans.emplace_back(lo, hi);
    if (in.floor_y_mm && X.y() - *in.floor_y_mm <= in.contact_skin_mm + 0.25 * h) {
      out.in_floor_layer[i] = 1;
      layer_spans.emplace_back(lo, hi);
    }
  }
  if (out.particles > 0) {
    out.back_x_mm = back;
    out.front_x_mm = front;
    out.length_mm = front - back;
  }
  // The extent of a set of intervals and the length they cover (gaps left out).
  const auto extent_and_cover = [](std::vector<std::pair<double, double>> spans, double& extent, double& covered) {
    extent = covered = 0;
    if (spans.empty()) return;
    std::sort(spans.begin(), spans.end());
    double run_lo = spans.front().first, run_hi = spans.front().second, last = run_hi;
    for (const auto& [lo, hi] : spans) {
      last = std::max(last, hi);
      if (lo > run_hi) {
        covered += run_hi - run_lo;
        run_lo = lo;
        run_hi = hi;
      } else {
        run_hi = std::max(run_hi, hi);
      }
    }
    covered += run_hi - run_lo;
    extent = last - spans.front().first;
  };
  out.floor_particles = static_cast<std::int64_t>(floor_spans.size());
  out.floor_layer_particles = static_cast<std::int64_t>(layer_spans.size());
  extent_and_cover(std::move(floor_spans), out.floor_length_mm, out.floor_covered_mm);
  extent_and_cover(std::move(layer_spans), out.floor_layer_length_mm, out.floor_layer_covered_mm);
  return out;
}

}  // namespace needle
