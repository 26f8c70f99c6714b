#include "solver/needle/rigid_needle.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "core/solver_error.h"

namespace needle {

RigidNeedle::RigidNeedle(const FeNeedle& needle, const InsertionProfile& profile, const Eigen::Vector3d& direction, double max_energy_error)
    : needle_(needle), profile_(profile), direction_(direction), max_energy_error_(max_energy_error) {
  profile_.validate();
  NEEDLE_REQUIRE(direction_.allFinite() && direction_.norm() > 0, "drive direction must be a non-zero vector");
  NEEDLE_REQUIRE(std::isfinite(max_energy_error) && max_energy_error > 0, "the rigid needle's max_energy_error must be positive");
  direction_.normalize();
  mass_ = needle.nodal_mass_g();
  x_ = needle.mesh().X;
  v_ = Eigen::MatrixX3d::Zero(x_.rows(), 3);
  force_ = Eigen::MatrixX3d::Zero(x_.rows(), 3);
}

void RigidNeedle::evaluate_loads(NeedleLoads& loads, const Eigen::MatrixX3d& velocity) {
  old_external_.swap(external_);
  external_.clear();
  force_.setZero(x_.rows(), 3);
  loads.needle_forces(x_, velocity, time_ms_, external_);
  for (const auto& [node, f] : external_) {
    NEEDLE_REQUIRE(node >= 0 && node < x_.rows(), "external needle force on a node that does not exist");
    force_.row(node) += f.transpose();
  }
  if (!force_.allFinite()) throw SolverError(fmt::format("the needle's loads became non-finite at t = {:.6g} ms", time_ms_));
}

void RigidNeedle::apply_loads(NeedleLoads& loads) {
  evaluate_loads(loads, v_);
  old_external_.clear();
}

void RigidNeedle::advance_to(double end_time_ms, NeedleLoads& loads) {
  const double dt = end_time_ms - time_ms_;
  if (!(dt > 1e-12 * std::max(1.0, std::abs(end_time_ms)))) return;
  // One step to the end: the nodes move by the profile's displacement over it, at its mean velocity.
  v_before_ = v_;
  const double drive_step = profile_.displacement_mm(time_ms_ + dt) - profile_.displacement_mm(time_ms_);
  v_half_ = (drive_step / dt) * direction_.transpose().replicate(x_.rows(), 1);
  x_ += dt * v_half_;
  time_ms_ += dt;
  old_force_.swap(force_);
  evaluate_loads(loads, v_half_);
  v_ = (profile_.velocity_mm_per_ms(time_ms_) * direction_).transpose().replicate(x_.rows(), 1);

  // The loads' work by the trapezoid rule through the mean velocity; the drive's reaction from
  // R dt = m (v(n+1) - v(n)) - (f(n) + f(n+1)) dt / 2 over all nodes.
  double external_work = 0;
  for (const NodalForces* list : {&old_external_, &external_})
    for (const auto& [node, f] : *list) external_work += 0.5 * dt * f.dot(v_half_.row(node).transpose());
  energy_.external_work_mJ += external_work;
  drive_reaction_.setZero();
  for (Eigen::Index i = 0; i < x_.rows(); ++i)
    for (int k = 0; k < 3; ++k) drive_reaction_[k] += (mass_[i] * (v_(i, k) - v_before_(i, k)) - 0.5 * (old_force_(i, k) + force_(i, k)) * dt) / dt;
  // The step may span a kink of the profile, where the mean velocity is not the mid-step one: the drive's
  // work is exactly what the motion needs, the change of kinetic energy less the loads' work.
  const double kinetic_before = energy_.kinetic_mJ;
  energy_.kinetic_mJ = 0.5 * mass_.dot(v_.rowwise().squaredNorm());
  energy_.drive_work_mJ += energy_.kinetic_mJ - kinetic_before - external_work;
  drive_impulse_ += dt * drive_reaction_;
  ++steps_;
  if (!std::isfinite(energy_.kinetic_mJ))
    throw SolverError(fmt::format("the needle's kinetic energy became non-finite at t = {:.6g} ms", time_ms_));
  const double work_scale = std::max(std::abs(energy_.drive_work_mJ), std::abs(energy_.external_work_mJ));
  if (work_scale > 1e-6 && energy_.balance_error() > max_energy_error_)
    throw SolverError(fmt::format("the needle's energy balance drifted by {:.3g} % at t = {:.6g} ms (limit {:.3g} %)",
                                  100 * energy_.balance_error(), time_ms_, 100 * max_energy_error_));
}

void RigidNeedle::add_summary(nlohmann::json& summary) const { summary["needle_time_step_ms"] = nullptr; }

}  // namespace needle
