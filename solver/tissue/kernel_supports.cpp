#include "solver/tissue/kernel_supports.h"

#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

SupportShape support_shape_from_name(const std::string& name) {
  if (name == "sphere") return SupportShape::sphere;
  if (name == "ellipsoid") return SupportShape::ellipsoid;
  throw InputError(fmt::format("kernel support '{}' is not one of sphere, ellipsoid", name));
}

std::string support_shape_name(SupportShape shape) { return shape == SupportShape::ellipsoid ? "ellipsoid" : "sphere"; }

KernelSupports::KernelSupports(const Eigen::VectorXd& sphere_radius_mm) : radius_mm(sphere_radius_mm.size(), 3), spherical(true) {
  radius_mm.col(0) = radius_mm.col(1) = radius_mm.col(2) = sphere_radius_mm;
}

KernelSupports KernelSupports::ellipsoids(const Eigen::MatrixX3d& semi_axes_mm) {
  KernelSupports s;
  s.radius_mm = semi_axes_mm;
  s.spherical = false;
  return s;
}

}  // namespace needle
