#pragma once
// The particles' kernel supports, the regions where a centre's RK shape function is not zero.
//  - sphere (the reference):  |x - X_j| < r_j, kernel phi(|x - X_j| / r_j), r_j = dilation x the largest of the
//    particle's neighbouring intervals;
//  - ellipsoid: semi-axes a_j = dilation x the particle's interval along each lattice axis, kernel
//    phi(|(x - X_j) ./ a_j|). On a lattice graded as a tensor product (mesher/particle_lattice.h: the path's
//    fine x intervals run through the whole block), a coarse particle's sphere of 1.8 x 0.4 mm covers about
//    four times the fine particles an ellipsoid of 1.8 intervals per axis does, and every one of them is an
//    entry of the shape functions, a bond and a term of every force gather. On a uniform lattice the two are
//    the same support.
// Both are exact for linear fields (the RK correction does not care about the weight's shape).
#include <Eigen/Dense>
#include <string>

namespace needle {

enum class SupportShape { sphere, ellipsoid };

SupportShape support_shape_from_name(const std::string& name);  // "sphere", "ellipsoid"; InputError otherwise
std::string support_shape_name(SupportShape shape);

struct KernelSupports {
  Eigen::MatrixX3d radius_mm;  // #centres by 3: the semi-axes along x, y, z (for a sphere the three are equal)
  bool spherical = true;

  KernelSupports() = default;
  // Spheres of the given radii (#centres), the reference; implicit, as every sphere-only caller passes radii.
  KernelSupports(const Eigen::VectorXd& sphere_radius_mm);  // NOLINT(google-explicit-constructor)
  static KernelSupports ellipsoids(const Eigen::MatrixX3d& semi_axes_mm);

  Eigen::Index size() const { return radius_mm.rows(); }
  double largest_mm() const { return radius_mm.size() ? radius_mm.maxCoeff() : 0.0; }
  // Whether point offset d = x - X_j lies strictly inside centre j's support.
  bool covers(Eigen::Index j, const Eigen::Vector3d& d) const {
    if (spherical) return d.squaredNorm() < radius_mm(j, 0) * radius_mm(j, 0);
    return (d.array() / radius_mm.row(j).transpose().array()).matrix().squaredNorm() < 1.0;
  }
};

}  // namespace needle
