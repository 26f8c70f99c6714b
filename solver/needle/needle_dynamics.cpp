#include "solver/needle/needle_dynamics.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "core/solver_error.h"

namespace needle {

double NeedleEnergy::balance_error() const {
  const double residual = kinetic_mJ + strain_mJ + held_mJ - initial_mJ - drive_work_mJ - cannula_work_mJ - external_work_mJ;
  const double scale = std::max({std::abs(kinetic_mJ), std::abs(strain_mJ), std::abs(initial_mJ), std::abs(drive_work_mJ),
                                 std::abs(cannula_work_mJ), std::abs(external_work_mJ), std::abs(held_mJ), 1e-300});
  return std::abs(residual) / scale;
}

NeedleSupports driven_base_supports(const TetMesh& mesh, const InsertionProfile& profile, const Eigen::Vector3d& direction) {
  NeedleSupports s;
  s.driven = nodes_with_tag(mesh, "base");
  if (mesh.tag_index("symmetry") >= 0) s.symmetry = nodes_with_tag(mesh, "symmetry");
  s.profile = profile;
  s.direction = direction;
  return s;
}

NeedleDynamics::NeedleDynamics(const FeNeedle& needle, NeedleSupports supports, const std::optional<CannulaOptions>& cannula,
                               const NeedleDynamicsOptions& options)
    : needle_(needle), supports_(std::move(supports)), options_(options) {
  supports_.profile.validate();
  NEEDLE_REQUIRE(options_.courant > 0 && options_.courant <= 1, "courant factor must lie in (0, 1]");
  NEEDLE_REQUIRE(supports_.direction.allFinite() && supports_.direction.norm() > 0, "drive direction must be a non-zero vector");
  supports_.direction.normalize();
  const int n = needle.num_nodes();
  mask_.assign(static_cast<size_t>(n), 0);
  auto mark = [&](const std::vector<int>& nodes, std::uint8_t bits, const char* what) {
    for (int i : nodes) {
      NEEDLE_REQUIRE(i >= 0 && i < n, fmt::format("{} node {} does not exist", what, i));
      mask_[static_cast<size_t>(i)] |= bits;
    }
  };
  mark(supports_.clamped, 7, "clamped");
  mark(supports_.symmetry, 4, "symmetry");
  mark(supports_.driven, 7, "driven");
  for (int i = 0; i < n; ++i)
    if (mask_[static_cast<size_t>(i)]) constrained_.push_back(i);
  v_before_.resize(static_cast<Eigen::Index>(constrained_.size()), 3);
  dt_ms_ = options_.courant * needle.stable_time_step_ms();
  mass_ = needle.nodal_mass_g();
  if (cannula && cannula->enabled) cannula_.emplace(*cannula, boundary_nodes(needle.mesh()), mass_, dt_ms_);
  x_ = needle.mesh().X;
  v_ = Eigen::MatrixX3d::Zero(n, 3);
  compute_forces(v_);
  energy_.initial_mJ = energy_.strain_mJ;
  a_ = force_.array().colwise() / mass_.array();
}

void NeedleDynamics::set_initial_state(const Eigen::MatrixX3d& x, const Eigen::MatrixX3d& v) {
  NEEDLE_REQUIRE(steps_ == 0, "the initial state can only be set before the first step");
  NEEDLE_REQUIRE(x.rows() == x_.rows() && v.rows() == v_.rows() && x.allFinite() && v.allFinite(),
                 "initial state: positions and velocities need one finite row per node");
  x_ = x;
  v_ = v;
  apply_supports(v_, 0.0);
  compute_forces(v_);
  a_ = force_.array().colwise() / mass_.array();
  const double strain = energy_.strain_mJ;  // from compute_forces
  energy_ = NeedleEnergy{};
  energy_.strain_mJ = strain;
  energy_.kinetic_mJ = 0.5 * mass_.dot(v_.rowwise().squaredNorm());
  energy_.initial_mJ = energy_.kinetic_mJ + energy_.strain_mJ;
}

void NeedleDynamics::advance_to(double end_time_ms) {
  while (time_ms_ < end_time_ms - 1e-12 * std::max(1.0, std::abs(end_time_ms))) step(end_time_ms);
}

void NeedleDynamics::apply_loads(NeedleLoads& loads) {
  for (const auto& [node, f] : external_) force_.row(node) -= f.transpose();
  external_.clear();
  loads_ = &loads;
  loads.needle_forces(x_, v_, time_ms_, external_);
  for (const auto& [node, f] : external_) {
    NEEDLE_REQUIRE(node >= 0 && node < x_.rows(), "external needle force on a node that does not exist");
    force_.row(node) += f.transpose();
  }
  a_ = force_.array().colwise() / mass_.array();
}

void NeedleDynamics::advance_to(double end_time_ms, NeedleLoads& loads) {
  loads_ = &loads;
  advance_to(end_time_ms);
}

void NeedleDynamics::add_summary(nlohmann::json& summary) const {
  summary["needle_time_step_ms"] = dt_ms_;
  summary["unscaled_needle_time_step_ms"] = needle_.unscaled_time_step_ms();
  summary["added_mass_percent"] = 100 * needle_.added_mass_g() / needle_.physical_mass_g();
}

void NeedleDynamics::apply_supports(Eigen::MatrixX3d& v, double t) const {
  const Eigen::RowVector3d drive = (supports_.profile.velocity_mm_per_ms(t) * supports_.direction).transpose();
  for (int i : supports_.clamped) v.row(i).setZero();
  for (int i : supports_.symmetry) v(i, 2) = 0.0;
  for (int i : supports_.driven) v.row(i) = drive;
}

void NeedleDynamics::compute_forces(const Eigen::MatrixX3d& velocity) {
  energy_.strain_mJ = needle_.internal_forces(x_, force_);
  cannula_force_.setZero(force_.rows(), 3);  // no allocation once sized
  if (cannula_) contact_ = cannula_->add_forces(x_, velocity, cannula_force_);
  force_ += cannula_force_;
  old_external_.swap(external_);
  external_.clear();
  if (loads_) {
    loads_->needle_forces(x_, velocity, time_ms_, external_);
    for (const auto& [node, f] : external_) force_.row(node) += f.transpose();
  }
  if (!force_.allFinite() || !std::isfinite(energy_.strain_mJ))
    throw SolverError(fmt::format("the needle's forces became non-finite at t = {:.6g} ms (step {})", time_ms_, steps_));
  if (contact_.max_penetration_mm > options_.max_penetration_mm)
    throw SolverError(fmt::format("the needle passed the cannula's bore by {:.3g} mm at t = {:.6g} ms (limit {:.3g} mm): "
                                  "runaway penetration", contact_.max_penetration_mm, time_ms_, options_.max_penetration_mm));
}

void NeedleDynamics::step(double end_time_ms) {
  const double dt = std::min(dt_ms_, end_time_ms - time_ms_);
  NEEDLE_REQUIRE(dt > 0, "the needle run has reached its end time");
  for (size_t k = 0; k < constrained_.size(); ++k) v_before_.row(static_cast<Eigen::Index>(k)) = v_.row(constrained_[k]);
  // Half kick and drift; driven nodes move exactly by the profile's displacement over the step.
  v_ += 0.5 * dt * a_;
  apply_supports(v_, time_ms_ + 0.5 * dt);
  const double drive_step = supports_.profile.displacement_mm(time_ms_ + dt) - supports_.profile.displacement_mm(time_ms_);
  for (int i : supports_.driven) v_.row(i) = (drive_step / dt) * supports_.direction.transpose();
  v_half_ = v_;
  x_ += dt * v_half_;
  time_ms_ += dt;

  old_force_.swap(force_);
  old_cannula_force_.swap(cannula_force_);
  compute_forces(v_half_);  // the cannula's friction reads the mid-step velocity
  a_ = force_.array().colwise() / mass_.array();
  v_ = v_half_ + 0.5 * dt * a_;
  apply_supports(v_, time_ms_);

  // Work over the step: the cannula's by the trapezoid rule; the reactions' on prescribed components
  // from R dt = m (v(n+1) - v(n)) - (f(n) + f(n+1)) dt / 2, through dx = v(n+1/2) dt.
  energy_.cannula_work_mJ += 0.5 * dt * ((old_cannula_force_ + cannula_force_).cwiseProduct(v_half_)).sum();
  double external_work = 0;
  for (const NodalForces* list : {&old_external_, &external_})
    for (const auto& [node, f] : *list) external_work += 0.5 * dt * f.dot(v_half_.row(node).transpose());
  energy_.external_work_mJ += external_work;
  double drive_work = 0;
  drive_reaction_.setZero();
  for (size_t c = 0; c < constrained_.size(); ++c) {
    const int i = constrained_[c];
    for (int k = 0; k < 3; ++k) {
      if (!(mask_[static_cast<size_t>(i)] & (1 << k))) continue;
      const double impulse =
          mass_[i] * (v_(i, k) - v_before_(static_cast<Eigen::Index>(c), k)) - 0.5 * (old_force_(i, k) + force_(i, k)) * dt;
      drive_work += impulse * v_half_(i, k);
      drive_reaction_[k] += impulse / dt;
    }
  }
  energy_.kinetic_mJ = 0.5 * mass_.dot(v_.rowwise().squaredNorm());
  energy_.drive_work_mJ += drive_work;
  drive_impulse_ += dt * drive_reaction_;
  ++steps_;
  if (!std::isfinite(energy_.kinetic_mJ))
    throw SolverError(fmt::format("the needle's kinetic energy became non-finite at t = {:.6g} ms", time_ms_));
  const double work_scale = std::max({std::abs(energy_.drive_work_mJ), std::abs(energy_.cannula_work_mJ), std::abs(energy_.external_work_mJ)});
  if (work_scale > 1e-6 && energy_.balance_error() > options_.max_energy_error)  // relative error of nJ is noise
    throw SolverError(fmt::format("the needle's energy balance drifted by {:.3g} % at t = {:.6g} ms (limit {:.3g} %)",
                                  100 * energy_.balance_error(), time_ms_, 100 * options_.max_energy_error));
}

}  // namespace needle
