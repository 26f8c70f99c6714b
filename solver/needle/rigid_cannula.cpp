#include "solver/needle/rigid_cannula.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

void CannulaOptions::validate(const std::string& where) const {
  auto positive = [&](double v, const char* name) {
    NEEDLE_REQUIRE(std::isfinite(v) && v > 0, fmt::format("{}: {} must be positive (got {})", where, name, v));
  };
  positive(outer_diameter_mm, "outer_diameter_mm");
  positive(wall_mm, "wall_mm");
  positive(length_mm, "length_mm");
  positive(penalty_scale, "penalty_scale");
  NEEDLE_REQUIRE(wall_mm < 0.5 * outer_diameter_mm, fmt::format("{}: the wall ({} mm) leaves no bore", where, wall_mm));
  NEEDLE_REQUIRE(std::isfinite(front_x_mm), fmt::format("{}: front_x_mm must be a number", where));
  NEEDLE_REQUIRE(std::isfinite(friction) && friction >= 0, fmt::format("{}: friction must be zero or positive (got {})", where, friction));
  NEEDLE_REQUIRE(penalty_scale <= 0.5, fmt::format("{}: penalty_scale above 0.5 would make contact limit the stable step", where));
}

RigidCannula::RigidCannula(const CannulaOptions& options, std::vector<int> nodes, const Eigen::VectorXd& mass, double dt_ms)
    : options_(options), nodes_(std::move(nodes)) {
  options_.validate();
  NEEDLE_REQUIRE(dt_ms > 0, "cannula contact needs a positive time step");
  for (int n : nodes_) {
    stiffness_.push_back(options_.penalty_scale * mass[n] / (dt_ms * dt_ms));
    damping_.push_back(0.5 * mass[n] / dt_ms);
  }
}

CannulaContact RigidCannula::add_forces(const Eigen::MatrixX3d& x, const Eigen::MatrixX3d& v, Eigen::MatrixX3d& force) const {
  CannulaContact c;
  const double r_in = options_.inner_radius_mm(), back = options_.front_x_mm - options_.length_mm;
  for (size_t k = 0; k < nodes_.size(); ++k) {
    const int n = nodes_[k];
    if (x(n, 0) < back || x(n, 0) > options_.front_x_mm) continue;
    const double r = std::hypot(x(n, 1), x(n, 2));
    const double penetration = r - r_in;
    if (penetration <= 0 || r == 0) continue;
    const Eigen::Vector3d radial(0, x(n, 1) / r, x(n, 2) / r);
    const double fn = stiffness_[k] * penetration;
    Eigen::Vector3d f = -fn * radial;
    const Eigen::Vector3d vel = v.row(n).transpose();
    const Eigen::Vector3d vt = vel - vel.dot(radial) * radial;
    const double speed = vt.norm();
    if (speed > 0 && options_.friction > 0) f -= std::min(options_.friction * fn, damping_[k] * speed) * vt / speed;
    force.row(n) += f.transpose();
    ++c.nodes_in_contact;
    c.max_penetration_mm = std::max(c.max_penetration_mm, penetration);
    c.normal_force_N += fn;
    c.force_N += f;
  }
  return c;
}

}  // namespace needle
