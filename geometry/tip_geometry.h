#pragma once
// The ideal (smooth-cylinder) solid a recipe describes, resolved to planes and a tip point:
//   solid = { |(y,z)| <= R, x >= base_x, n_i . (p - p_i) <= 0 for every facet i } minus the groove box.
// Everything downstream (the CGAL solid, exact areas, sections) starts from this.
#include <Eigen/Dense>
#include <optional>
#include <string>
#include <vector>

#include "geometry/grinding_recipe.h"

namespace needle {

struct FacetPlane {
  std::string name;
  double tilt_deg = 0.0;
  double rotation_deg = 0.0;
  Eigen::Vector3d normal;  // outward unit normal (sin t, cos t cos r, cos t sin r)
  Eigen::Vector3d point;   // a point on the plane, mm

  double signed_distance(const Eigen::Vector3d& p) const { return normal.dot(p - point); }
};

// The removed groove: x in [back_x, front_x] and y >= floor_y.
struct GrooveBox {
  double floor_y_mm = 0.0;
  double front_x_mm = 0.0;
  double back_x_mm = 0.0;
  bool contains(const Eigen::Vector3d& p) const {
    return p.x() >= back_x_mm && p.x() <= front_x_mm && p.y() >= floor_y_mm;
  }
};

struct TipGeometry {
  std::string name;
  double radius_mm = 0.5;
  double base_x_mm = -40.0;
  std::vector<FacetPlane> facets;
  Eigen::Vector3d tip_point{0, 0, 0};  // A; x = 0 by convention
  std::optional<GrooveBox> groove;

  // d_a = y(A) - y(groove floor); absent without a groove.
  std::optional<double> d_a_mm() const;
  // True if p belongs to the ideal solid (closed set, with tolerance tol_mm).
  bool contains(const Eigen::Vector3d& p, double tol_mm = 1e-9) const;
};

Eigen::Vector3d facet_outward_normal(double tilt_deg, double rotation_deg);

// Where the common line of two planes pierces the cylinder |(y,z)| = radius: zero or two points.
std::vector<Eigen::Vector3d> plane_pair_on_cylinder(const FacetPlane& a, const FacetPlane& b, double radius);

// Resolves the recipe: places every plane, finds the most distal point of the solid analytically
// (the maximum of x over the convex tip region) and shifts the frame so that x(A) = 0.
// Throws InputError if the recipe is invalid, the tip is blunt (no single most distal point) or the
// through-tip facets do not converge at the requested tip point.
TipGeometry resolve_tip(const GrindingRecipe& recipe);

// A flat-ended rod with no facets ground (the end face is tagged `end`, A is its centre): the
// beam-theory check case for the needle's FE model.
TipGeometry plain_rod_tip(double diameter_mm, double length_mm);

}  // namespace needle
