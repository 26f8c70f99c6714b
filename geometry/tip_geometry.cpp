#include "geometry/tip_geometry.h"

#include <Eigen/Dense>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {
namespace {

constexpr double kPi = 3.14159265358979323846;

double deg_to_rad(double deg) { return deg * kPi / 180.0; }

// Feasible for the convex tip region: inside the cylinder and behind every facet plane.
bool in_convex_region(const std::vector<FacetPlane>& planes, double radius, const Eigen::Vector3d& p,
                      double tol) {
  if (std::hypot(p.y(), p.z()) > radius + tol) return false;
  for (const FacetPlane& plane : planes)
    if (plane.signed_distance(p) > tol) return false;
  return true;
}

// All candidate maximisers of x over { |(y,z)| <= R } intersected with the facet half-spaces.
// The KKT conditions leave three kinds: three planes meet (a vertex), two planes meet on the
// cylinder, or one plane touches the cylinder where its ellipse is most distal.
std::vector<Eigen::Vector3d> distal_candidates(const std::vector<FacetPlane>& planes, double radius) {
  std::vector<Eigen::Vector3d> candidates;
  const int n = static_cast<int>(planes.size());
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& ni = planes[i].normal;
    const Eigen::Vector2d radial(ni.y(), ni.z());
    if (radial.norm() > 1e-14) {
      const Eigen::Vector2d yz = -radius * radial.normalized();
      const double x = (ni.dot(planes[i].point) - ni.y() * yz.x() - ni.z() * yz.y()) / ni.x();
      candidates.emplace_back(x, yz.x(), yz.y());
    }
    for (int j = i + 1; j < n; ++j) {
      const Eigen::Vector3d& nj = planes[j].normal;
      for (const Eigen::Vector3d& p : plane_pair_on_cylinder(planes[i], planes[j], radius)) candidates.push_back(p);
      for (int k = j + 1; k < n; ++k) {
        const Eigen::Vector3d& nk = planes[k].normal;
        Eigen::Matrix3d T;
        T << ni.transpose(), nj.transpose(), nk.transpose();
        if (std::abs(T.determinant()) < 1e-12) continue;
        candidates.push_back(T.partialPivLu().solve(Eigen::Vector3d(
            ni.dot(planes[i].point), nj.dot(planes[j].point), nk.dot(planes[k].point))));
      }
    }
  }
  return candidates;
}

}  // namespace

std::vector<Eigen::Vector3d> plane_pair_on_cylinder(const FacetPlane& a, const FacetPlane& b, double radius) {
  const Eigen::Vector3d dir = a.normal.cross(b.normal);
  const double qa = dir.y() * dir.y() + dir.z() * dir.z();
  if (dir.norm() < 1e-12 || qa < 1e-14) return {};
  Eigen::Matrix3d M;
  M << a.normal.transpose(), b.normal.transpose(), dir.transpose();
  const Eigen::Vector3d p0 =
      M.fullPivLu().solve(Eigen::Vector3d(a.normal.dot(a.point), b.normal.dot(b.point), 0.0));
  // |p0_yz + t dir_yz| = radius
  const double qb = 2.0 * (p0.y() * dir.y() + p0.z() * dir.z());
  const double qc = p0.y() * p0.y() + p0.z() * p0.z() - radius * radius;
  const double disc = qb * qb - 4 * qa * qc;
  if (disc < 0.0) return {};
  const double root = std::sqrt(disc);
  return {p0 + (-qb + root) / (2 * qa) * dir, p0 + (-qb - root) / (2 * qa) * dir};
}

Eigen::Vector3d facet_outward_normal(double tilt_deg, double rotation_deg) {
  const double t = deg_to_rad(tilt_deg), r = deg_to_rad(rotation_deg);
  return {std::sin(t), std::cos(t) * std::cos(r), std::cos(t) * std::sin(r)};
}

std::optional<double> TipGeometry::d_a_mm() const {
  if (!groove) return std::nullopt;
  return tip_point.y() - groove->floor_y_mm;
}

bool TipGeometry::contains(const Eigen::Vector3d& p, double tol) const {
  if (p.x() < base_x_mm - tol) return false;
  if (!in_convex_region(facets, radius_mm, p, tol)) return false;
  if (groove) {
    const GrooveBox& g = *groove;
    // strictly inside the removed box (by more than tol) means outside the solid
    if (p.x() > g.back_x_mm + tol && p.x() < g.front_x_mm - tol && p.y() > g.floor_y_mm + tol)
      return false;
  }
  return true;
}

TipGeometry resolve_tip(const GrindingRecipe& recipe) {
  validate_recipe(recipe);
  TipGeometry tip;
  tip.name = recipe.name;
  tip.radius_mm = 0.5 * recipe.rod.diameter_mm;
  const double R = tip.radius_mm;

  bool any_through_tip = false;
  for (const Grind& grind : recipe.grinds) {
    FacetPlane plane;
    plane.name = grind.name;
    plane.tilt_deg = grind.tilt_deg;
    plane.rotation_deg = grind.rotation_deg;
    plane.normal = facet_outward_normal(grind.tilt_deg, grind.rotation_deg);
    if (grind.through_tip) {
      any_through_tip = true;
      plane.point = Eigen::Vector3d(0.0, *recipe.tip_y_mm, 0.0);
    } else {
      const double r = deg_to_rad(grind.rotation_deg), reach = R - grind.depth_mm;
      plane.point = Eigen::Vector3d(0.0, reach * std::cos(r), reach * std::sin(r));
    }
    tip.facets.push_back(plane);
  }

  // Most distal point of the convex tip region.
  const double tol = 1e-10;
  double best_x = -std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector3d> feasible;
  for (const Eigen::Vector3d& p : distal_candidates(tip.facets, R)) {
    if (!in_convex_region(tip.facets, R, p, tol)) continue;
    feasible.push_back(p);
    best_x = std::max(best_x, p.x());
  }
  NEEDLE_REQUIRE(!feasible.empty(), "the facets do not form a tip: no point of the rod lies behind all of them");
  Eigen::Vector3d apex = Eigen::Vector3d::Constant(std::nan(""));
  for (const Eigen::Vector3d& p : feasible) {
    if (p.x() < best_x - 1e-9) continue;
    if (std::isnan(apex.x())) {
      apex = p;
    } else {
      NEEDLE_REQUIRE((p - apex).norm() < 1e-6,
                     fmt::format("the facets do not converge to a single tip point: the tip is blunt, "
                                 "with distal points ({:.4f}, {:.4f}, {:.4f}) and ({:.4f}, {:.4f}, {:.4f}) mm",
                                 apex.x(), apex.y(), apex.z(), p.x(), p.y(), p.z()));
    }
  }
  if (any_through_tip) {
    const Eigen::Vector3d target(0.0, *recipe.tip_y_mm, 0.0);
    NEEDLE_REQUIRE((apex - target).norm() < 1e-7,
                   fmt::format("the facets cannot converge at tip point A = (0, {:.4f}, 0) mm: the most "
                               "distal point of the ground rod is ({:.4f}, {:.4f}, {:.4f}) mm; change the "
                               "tilts or rotations so the facets close around A",
                               target.y(), apex.x(), apex.y(), apex.z()));
    apex = target;  // exact by construction: every through-tip plane contains it
  }
  // Shift so that x(A) = 0.
  const Eigen::Vector3d shift(-apex.x(), 0.0, 0.0);
  for (FacetPlane& plane : tip.facets) plane.point += shift;
  tip.tip_point = apex + shift;
  tip.base_x_mm = -recipe.rod.length_mm;
  if (recipe.groove) {
    GrooveBox box;
    box.floor_y_mm = groove_floor_y_mm(recipe.rod, *recipe.groove);
    box.front_x_mm = -recipe.groove->start_behind_tip_mm;
    box.back_x_mm = box.front_x_mm - recipe.groove->length_mm;
    tip.groove = box;
  }
  return tip;
}

TipGeometry plain_rod_tip(double diameter_mm, double length_mm) {
  NEEDLE_REQUIRE(std::isfinite(diameter_mm) && diameter_mm > 0, "rod diameter must be positive");
  NEEDLE_REQUIRE(std::isfinite(length_mm) && length_mm > diameter_mm,
                 fmt::format("rod length {} mm must exceed its diameter", length_mm));
  TipGeometry tip;
  tip.name = "rod";
  tip.radius_mm = 0.5 * diameter_mm;
  tip.base_x_mm = -length_mm;
  FacetPlane end;
  end.name = "end";
  end.tilt_deg = 90.0;
  end.normal = facet_outward_normal(90.0, 0.0);
  end.point = Eigen::Vector3d::Zero();
  tip.facets.push_back(end);
  tip.tip_point = Eigen::Vector3d::Zero();
  return tip;
}

}  // namespace needle
