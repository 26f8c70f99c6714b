#include "geometry/exact_measures.h"

#include "geometry/rod_tessellation.h"

#include <Eigen/Geometry>
#include <cmath>
#include <functional>

namespace needle {
namespace {

constexpr double kPi = 3.14159265358979323846;
using Polygon2 = std::vector<Eigen::Vector2d>;

// Keeps the part of a convex polygon where a*u + b*v + c <= 0 (Sutherland-Hodgman, one edge).
Polygon2 clip_half_plane(const Polygon2& poly, double a, double b, double c) {
  Polygon2 out;
  const size_t n = poly.size();
  if (n == 0) return out;
  out.reserve(n + 2);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = poly[i];
    const Eigen::Vector2d& q = poly[(i + 1) % n];
    const double fp = a * p.x() + b * p.y() + c, fq = a * q.x() + b * q.y() + c;
    if (fp <= 0) out.push_back(p);
    if ((fp < 0 && fq > 0) || (fp > 0 && fq < 0)) out.push_back(p + fp / (fp - fq) * (q - p));
  }
  return out;
}

double polygon_area(const Polygon2& poly) {
  double twice = 0;
  for (size_t i = 0, n = poly.size(); i < n; ++i) {
    const Eigen::Vector2d& p = poly[i];
    const Eigen::Vector2d& q = poly[(i + 1) % n];
    twice += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * std::abs(twice);
}

// A plane p(u, v) = origin + u*eu + v*ev; a 3-D half-space n.(p - q) <= 0 becomes a 2-D half-plane.
struct PlaneFrame {
  Eigen::Vector3d origin, eu, ev;
  Eigen::Vector3d at(const Eigen::Vector2d& uv) const { return origin + uv.x() * eu + uv.y() * ev; }
  Polygon2 clip(const Polygon2& poly, const Eigen::Vector3d& n, const Eigen::Vector3d& q) const {
    return clip_half_plane(poly, n.dot(eu), n.dot(ev), n.dot(origin - q));
  }
};

// Clips `region` (in `frame`) by every constraint of the ideal solid except the groove and the
// facet `skip`; returns area(region) - area(region inside the groove box).
double area_outside_groove(const TipGeometry& tip, const PlaneFrame& frame, Polygon2 region, int skip,
                           bool half_model) {
  const Eigen::Vector3d ex(1, 0, 0), ey(0, 1, 0), ez(0, 0, 1);
  for (int j = 0; j < static_cast<int>(tip.facets.size()); ++j)
    if (j != skip) region = frame.clip(region, tip.facets[j].normal, tip.facets[j].point);
  region = frame.clip(region, -ex, Eigen::Vector3d(tip.base_x_mm, 0, 0));
  if (half_model) region = frame.clip(region, -ez, Eigen::Vector3d::Zero());
  double area = polygon_area(region);
  if (tip.groove) {
    const GrooveBox& g = *tip.groove;
    Polygon2 inside = frame.clip(region, ex, Eigen::Vector3d(g.front_x_mm, 0, 0));
    inside = frame.clip(inside, -ex, Eigen::Vector3d(g.back_x_mm, 0, 0));
    inside = frame.clip(inside, -ey, Eigen::Vector3d(0, g.floor_y_mm, 0));
    area -= polygon_area(inside);
  }
  return area;
}

}  // namespace

double exact_facet_area_mm2(const TipGeometry& tip, int facet_index, const ExactOptions& options) {
  const FacetPlane& plane = tip.facets.at(facet_index);
  const Eigen::Vector3d& n = plane.normal;
  PlaneFrame frame;
  frame.origin = plane.point;
  frame.eu = n.cross(Eigen::Vector3d(0, 0, 1));
  if (frame.eu.norm() < 1e-8) frame.eu = n.cross(Eigen::Vector3d(0, 1, 0));
  frame.eu.normalize();
  frame.ev = n.cross(frame.eu);
  // The plane cuts the cylinder in an ellipse: point at angle psi has y = R cos psi, z = R sin psi,
  // and x from the plane equation (n_x = sin(tilt) > 0).
  Polygon2 ellipse;
  ellipse.reserve(options.circle_vertices);
  const double R = tip.radius_mm;
  for (int k = 0; k < options.circle_vertices; ++k) {
    const double psi = 2 * kPi * k / options.circle_vertices;
    const double y = R * std::cos(psi), z = R * std::sin(psi);
    const double x = (n.dot(plane.point) - n.y() * y - n.z() * z) / n.x();
    const Eigen::Vector3d d = Eigen::Vector3d(x, y, z) - frame.origin;
    ellipse.emplace_back(d.dot(frame.eu), d.dot(frame.ev));
  }
  return area_outside_groove(tip, frame, std::move(ellipse), facet_index, options.half_model);
}

SectionProperties exact_section(const TipGeometry& tip, double x_mm, const ExactOptions& options) {
  const double R = tip.radius_mm;
  Polygon2 region;
  if (x_mm >= tip.base_x_mm) {
    region.reserve(options.circle_vertices);
    for (int k = 0; k < options.circle_vertices; ++k) {
      const double psi = 2 * kPi * k / options.circle_vertices;
      region.emplace_back(R * std::cos(psi), R * std::sin(psi));
    }
  }
  PlaneFrame frame{Eigen::Vector3d(x_mm, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)};
  for (const FacetPlane& plane : tip.facets) region = frame.clip(region, plane.normal, plane.point);
  if (options.half_model) region = frame.clip(region, Eigen::Vector3d(0, 0, -1), Eigen::Vector3d::Zero());
  if (tip.groove && x_mm > tip.groove->back_x_mm && x_mm < tip.groove->front_x_mm)
    region = frame.clip(region, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, tip.groove->floor_y_mm, 0));
  SectionIntegrals integrals;
  // Orient counter-clockwise in (y, z): the circle is generated that way and clipping keeps order.
  for (size_t i = 0, n = region.size(); i < n; ++i)
    integrals.add_segment(region[i].x(), region[i].y(), region[(i + 1) % n].x(), region[(i + 1) % n].y());
  return integrals.finish(x_mm);
}

double exact_volume_mm3(const TipGeometry& tip, const ExactOptions& options) {
  // Section area is smooth between the base, the groove walls and the tip region's kinks; integrate
  // each stretch with composite Simpson on a fine grid (the tip region, where facets vary, finest).
  ExactOptions coarse = options;
  coarse.circle_vertices = std::min(options.circle_vertices, 2048);  // area error ~5e-6
  auto area = [&](double x) { return exact_section(tip, x, coarse).area_mm2; };
  auto simpson = [&](double a, double b, int intervals) {
    if (b <= a) return 0.0;
    intervals += intervals % 2;
    const double h = (b - a) / intervals;
    double sum = area(a) + area(b);
    for (int i = 1; i < intervals; ++i) sum += (i % 2 ? 4.0 : 2.0) * area(a + i * h);
    return sum * h / 3.0;
  };
  // Find where the facets stop cutting: the heel of the tip, searched on the plain rod.
  const double heel_x = tip_heel_x_mm(tip);
  std::vector<double> breaks = {tip.base_x_mm, heel_x, 0.0};
  if (tip.groove) {
    breaks.push_back(std::max(tip.groove->back_x_mm, tip.base_x_mm));
    breaks.push_back(std::min(tip.groove->front_x_mm, 0.0));
  }
  std::sort(breaks.begin(), breaks.end());
  double volume = 0.0;
  for (size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double a = breaks[i], b = breaks[i + 1];
    if (b - a < 1e-12) continue;
    const bool in_tip = a >= heel_x - 1e-12;
    // Inside a stretch the area is either constant (plain rod or groove) or varies with the facets.
    const int intervals = in_tip ? 2000 : 2;
    volume += simpson(a + 1e-12, b - 1e-12, intervals);
  }
  return volume;
}

}  // namespace needle
