#include "geometry/rod_tessellation.h"

#include <algorithm>
#include <cmath>

namespace needle {
namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kMergeAngle = 1e-4;    // rad: special angles closer than this share one edge
constexpr double kFinestAngle = 3.5e-3; // rad: never subdivide finer than this (about 0.2 degree)

double wrap(double angle) {
  angle = std::fmod(angle, 2 * kPi);
  return angle < 0 ? angle + 2 * kPi : angle;
}
}  // namespace

std::vector<double> rod_edge_angles(const TipGeometry& tip, const TessellationOptions& options) {
  const double R = tip.radius_mm;
  std::vector<double> special = {0.0, kPi};
  if (tip.groove && std::abs(tip.groove->floor_y_mm) < R) {
    const double psi = std::acos(tip.groove->floor_y_mm / R);
    special.push_back(psi);
    special.push_back(2 * kPi - psi);
  }
  // Where two facets' common line pierces the cylinder on the solid's surface.
  const int n = static_cast<int>(tip.facets.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (const Eigen::Vector3d& p : plane_pair_on_cylinder(tip.facets[i], tip.facets[j], R))
        if (tip.contains(p, 1e-9)) special.push_back(wrap(std::atan2(p.z(), p.y())));
  std::sort(special.begin(), special.end());
  std::vector<double> corners;
  for (double angle : special)
    if (corners.empty() || angle - corners.back() > kMergeAngle) corners.push_back(angle);
  if (corners.size() > 1 && 2 * kPi - corners.back() + corners.front() <= kMergeAngle) corners.pop_back();

  const double max_step = 2.0 * std::acos(1.0 - options.chord_tolerance_mm / R);
  std::vector<double> angles;
  for (size_t k = 0; k < corners.size(); ++k) {
    const double start = corners[k];
    const double end = (k + 1 < corners.size()) ? corners[k + 1] : corners.front() + 2 * kPi;
    const double gap = end - start;
    const int by_tolerance = static_cast<int>(std::ceil(gap / max_step));
    const int by_arc = std::min(options.min_segments_per_arc, static_cast<int>(gap / kFinestAngle));
    const int segments = std::max({by_tolerance, by_arc, 1});
    for (int s = 0; s < segments; ++s) angles.push_back(start + gap * s / segments);
  }
  return angles;
}

double tip_heel_x_mm(const TipGeometry& tip) {
  double heel_x = 0.0;
  for (const FacetPlane& plane : tip.facets) {
    // Most proximal point of the plane inside the cylinder: x = (n.q - R |n_yz|) / n_x.
    const double radial = std::hypot(plane.normal.y(), plane.normal.z());
    heel_x = std::min(heel_x, (plane.normal.dot(plane.point) - tip.radius_mm * radial) / plane.normal.x());
  }
  return std::max(heel_x, tip.base_x_mm);
}

std::vector<double> rod_ring_positions(const TipGeometry& tip, const TessellationOptions& options,
                                       const std::vector<double>& extra_stops) {
  std::vector<double> stops = {tip.base_x_mm, 0.5 * tip.radius_mm};  // blank runs a little past A
  stops.insert(stops.end(), extra_stops.begin(), extra_stops.end());
  if (tip.groove) {
    stops.push_back(tip.groove->back_x_mm);
    stops.push_back(tip.groove->front_x_mm);
  }
  // Fine rings where the facets cut (from half a millimetre behind the heel), coarse elsewhere.
  const double fine_from_x = std::max(tip.base_x_mm, tip_heel_x_mm(tip) - 0.5);
  stops.push_back(fine_from_x);
  std::sort(stops.begin(), stops.end());
  stops.erase(std::unique(stops.begin(), stops.end()), stops.end());
  std::vector<double> rings;
  for (size_t k = 0; k + 1 < stops.size(); ++k) {
    const double a = stops[k], b = stops[k + 1];
    const double spacing = a >= fine_from_x ? options.axial_spacing_mm : options.shaft_axial_spacing_mm;
    const int segments = std::max(1, static_cast<int>(std::ceil((b - a) / spacing)));
    for (int s = 0; s < segments; ++s) rings.push_back(a + (b - a) * s / segments);
  }
  rings.push_back(stops.back());
  return rings;
}

TriSurface tessellate_rod(const TipGeometry& tip, const std::vector<double>& all_angles,
                          const std::vector<double>& rings, bool half_model) {
  std::vector<double> angles;
  for (double angle : all_angles)
    if (!half_model || angle <= kPi + 1e-12) angles.push_back(angle);
  const int na = static_cast<int>(angles.size()), nr = static_cast<int>(rings.size());
  const double R = tip.radius_mm;
  // Exact positions where it matters: the groove floor edges and the symmetry plane.
  std::vector<double> cy(na), cz(na);
  for (int a = 0; a < na; ++a) {
    cy[a] = R * std::cos(angles[a]);
    cz[a] = R * std::sin(angles[a]);
    if (std::abs(angles[a]) < 1e-15) cz[a] = 0.0, cy[a] = R;
    if (std::abs(angles[a] - kPi) < 1e-12) cz[a] = 0.0, cy[a] = -R;
    if (tip.groove && std::abs(cy[a] - tip.groove->floor_y_mm) < 1e-12) {
      cy[a] = tip.groove->floor_y_mm;
      cz[a] = std::copysign(std::sqrt(R * R - cy[a] * cy[a]), cz[a]);
    }
  }
  // Vertices: na per ring, then one axis vertex per ring (cap fan centres; in the half model also
  // the middle of the symmetry face, so it conforms to the caps).
  const int axis0 = na * nr;
  std::vector<Eigen::Vector3d> V;
  std::vector<Eigen::Vector3i> F;
  for (int r = 0; r < nr; ++r)
    for (int a = 0; a < na; ++a) V.emplace_back(rings[r], cy[a], cz[a]);
  for (int r = 0; r < nr; ++r) V.emplace_back(rings[r], 0.0, 0.0);
  const int wrap_count = half_model ? na - 1 : na;  // side strips between consecutive angles
  for (int r = 0; r + 1 < nr; ++r)
    for (int a = 0; a < wrap_count; ++a) {
      const int a2 = (a + 1) % na;
      const int v00 = r * na + a, v01 = r * na + a2, v10 = (r + 1) * na + a, v11 = (r + 1) * na + a2;
      // Outward normal: angle increases counter-clockwise seen from +x, x increases along the rod.
      F.emplace_back(v00, v01, v11);
      F.emplace_back(v00, v11, v10);
    }
  const int last = nr - 1;
  for (int a = 0; a < wrap_count; ++a) {
    const int a2 = (a + 1) % na;
    F.emplace_back(axis0, a2, a);                                    // base cap faces -x
    F.emplace_back(axis0 + last, last * na + a, last * na + a2);     // front cap faces +x
  }
  if (half_model) {
    // Symmetry face z = 0 (normal -z): per ring the points y = +R (angle 0), 0 (axis), -R (angle pi).
    const int top = 0, bottom = na - 1;
    for (int r = 0; r + 1 < nr; ++r) {
      const int t0 = r * na + top, t1 = (r + 1) * na + top, c0 = axis0 + r, c1 = axis0 + r + 1;
      const int b0 = r * na + bottom, b1 = (r + 1) * na + bottom;
      F.emplace_back(t0, t1, c1);
      F.emplace_back(t0, c1, c0);
      F.emplace_back(c0, c1, b1);
      F.emplace_back(c0, b1, b0);
    }
  }
  TriSurface rod;
  rod.V.resize(V.size(), 3);
  for (size_t i = 0; i < V.size(); ++i) rod.V.row(i) = V[i].transpose();
  rod.F.resize(F.size(), 3);
  for (size_t i = 0; i < F.size(); ++i) rod.F.row(i) = F[i].transpose();
  rod.face_tag = Eigen::VectorXi::Zero(rod.F.rows());
  rod.tag_names = {"untagged"};
  return rod;
}

}  // namespace needle
