#include "solver/insertion/groove_fill.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "core/input_error.h"

namespace needle {

bool in_groove_section(const GrooveBox& g, double R, const Eigen::Vector3d& X, double h) {
  const double y = X.y(), floor = g.floor_y_mm;
  if (y < floor - 0.5 * h || y >= R) return false;
  const double y_width = std::max(y, floor);
  return std::abs(X.z()) <= std::sqrt(std::max(0.0, R * R - y_width * y_width));
}

GrooveFill measure_groove_fill(const GrooveFillInput& in) {
  NEEDLE_REQUIRE(in.slice_mm > 0, "groove fill: the slice length must be positive");
  NEEDLE_REQUIRE(in.spacing_mm.size() == in.reference_points.size() && in.touches_floor.size() == in.reference_points.size(),
                 "groove fill: one spacing and one contact flag per particle");
  const GrooveBox& g = in.groove;
  const double R = in.radius_mm, floor = g.floor_y_mm;
  NEEDLE_REQUIRE(floor < R, "groove fill: the groove floor lies above the rod");
  GrooveFill out;
  const double lo = std::max(g.back_x_mm, in.tissue_min_x_mm), hi = std::min(g.front_x_mm, in.tissue_max_x_mm);
  if (!(hi > lo)) return out;
  out.length_in_tissue_mm = hi - lo;
  const int slices = std::max(1, static_cast<int>(std::ceil((hi - lo) / in.slice_mm)));
  const double slice = (hi - lo) / slices;
  std::vector<double> bottom(static_cast<size_t>(slices), std::numeric_limits<double>::infinity());
  std::vector<std::uint8_t> touched(static_cast<size_t>(slices), 0);
  for (size_t i = 0; i < in.reference_points.size(); ++i) {
    const Eigen::Vector3d& X = in.reference_points[i];
    if (!X.allFinite()) continue;
    const double h = in.spacing_mm[i];
    if (X.x() + 0.5 * h < lo || X.x() - 0.5 * h > hi) continue;
    if (!in_groove_section(g, R, X, h)) continue;
    const double y = X.y();
    ++out.particles_in_groove;
    const int first = std::max(0, static_cast<int>(std::floor((X.x() - 0.5 * h - lo) / slice)));
    const int last = std::min(slices - 1, static_cast<int>(std::floor((X.x() + 0.5 * h - lo) / slice)));
    for (int k = first; k <= last; ++k) {
      bottom[static_cast<size_t>(k)] = std::min(bottom[static_cast<size_t>(k)], std::max(floor, y - 0.5 * h));
      if (in.touches_floor[i]) touched[static_cast<size_t>(k)] = 1;
    }
  }
  const double depth = R - floor;
  double fill = 0, gap = 0;
  int touched_count = 0;
  for (int k = 0; k < slices; ++k) {
    const double b = bottom[static_cast<size_t>(k)];
    const double bottom_y = std::isfinite(b) ? std::min(b, R) : R;
    fill += (R - bottom_y) / depth;
    gap += bottom_y - floor;
    touched_count += touched[static_cast<size_t>(k)];
  }
  out.groove_fill = fill / slices;
  out.mean_gap_mm = gap / slices;
  out.floor_contact_fraction = static_cast<double>(touched_count) / slices;
  return out;
}

}  // namespace needle
