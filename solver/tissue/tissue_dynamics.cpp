#include "solver/tissue/tissue_dynamics.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"
#include "core/parallel.h"
#include "core/solver_error.h"

namespace needle {
namespace {
constexpr double kOnPlaneMm = 1e-9;  // an open symmetry particle this close to z = 0 rests on the plane
}  // namespace

double EnergyBalance::relative_error() const {
  const double residual = kinetic_mJ - initial_kinetic_mJ - model_work_mJ - body_work_mJ - external_work_mJ - constraint_work_mJ -
                          mass_scaling_mJ;
  const double scale = std::max({std::abs(kinetic_mJ), std::abs(initial_kinetic_mJ), std::abs(model_work_mJ), std::abs(body_work_mJ),
                                 std::abs(external_work_mJ), std::abs(constraint_work_mJ), std::abs(mass_scaling_mJ), 1e-300});
  return std::abs(residual) / scale;
}

TissueDynamics::TissueDynamics(SpgTissue& tissue, std::vector<VelocityConstraint> constraints,
                               const Eigen::Vector3d& body_acceleration)
    : tissue_(tissue), constraints_(std::move(constraints)), body_acceleration_(body_acceleration) {
  const TissueParticles& p = tissue_.particles();
  for (const VelocityConstraint& c : constraints_) {
    NEEDLE_REQUIRE(c.axis >= 0 && c.axis < 3, "velocity constraint axis must be 0, 1 or 2");
    NEEDLE_REQUIRE(static_cast<bool>(c.velocity_mm_per_ms), "velocity constraint without a velocity function");
    NEEDLE_REQUIRE(c.scale.empty() || c.scale.size() == c.particles.size(), "velocity constraint scale needs one value per particle");
    for (std::int32_t i : c.particles) NEEDLE_REQUIRE(i >= 0 && i < p.size(), "velocity constraint names a particle that does not exist");
  }
  NEEDLE_REQUIRE(body_acceleration.allFinite(), "body acceleration must be finite");
  constrained_mask_.assign(static_cast<size_t>(p.size()), 0);
  for (std::int64_t i = 0; i < p.size(); ++i) {
    const std::uint8_t f = p.flags[static_cast<size_t>(i)];
    if (f & kParticleFixed) constrained_mask_[static_cast<size_t>(i)] = 7;
    else if (f & kParticleSymmetry) constrained_mask_[static_cast<size_t>(i)] |= 4;
  }
  for (const VelocityConstraint& c : constraints_)
    for (std::int32_t i : c.particles) constrained_mask_[static_cast<size_t>(i)] |= static_cast<std::uint8_t>(1 << c.axis);
  for (std::int64_t i = 0; i < p.size(); ++i)
    if (constrained_mask_[static_cast<size_t>(i)]) constrained_.push_back(static_cast<std::int32_t>(i));
  constrained_velocity_before_.resize(constrained_.size());
  constrained_velocity_half_.resize(constrained_.size());
  displacement_.resize(static_cast<size_t>(p.size()));
  external_force_.assign(static_cast<size_t>(p.size()), Vec3d::Zero());
  tissue_.compute_forces(0.0);
  acceleration_.resize(static_cast<size_t>(p.size()));
  for (std::int64_t i = 0; i < p.size(); ++i)
    acceleration_[static_cast<size_t>(i)] = p.force_N[static_cast<size_t>(i)] / p.mass_g[static_cast<size_t>(i)] + body_acceleration_;
  apply_constraints(tissue_.particles().velocity_mm_per_ms, 0.0, 0.0);
  energy_.initial_kinetic_mJ = energy_.kinetic_mJ = kinetic_energy_mJ();
}

void TissueDynamics::apply_constraints(std::vector<Vec3d>& v, double time_ms, double drift_dt_ms) {
  const TissueParticles& p = tissue_.particles();
  if (drift_dt_ms == 0) {
    // After the drift, the particles that landed this step and still move down are stopped below; that
    // second impulse's work, corrected as the first's.
    for (const Landing& l : landed_) {
      const size_t s = static_cast<size_t>(l.particle);
      const double before = v[s].z();
      if (p.position_mm[s].z() <= kOnPlaneMm && before < 0)
        impact_work_correction_mJ_ += -0.5 * p.mass_g[s] * before * before + p.mass_g[s] * before * l.v_half_z;
    }
  }
  for (std::int64_t i = 0; i < p.size(); ++i) {
    const size_t s = static_cast<size_t>(i);
    const std::uint8_t f = p.flags[s];
    if (f & kParticleFixed) v[s].setZero();
    else if (f & kParticleOpenSymmetry) {
      // z >= 0. On the plane the particle is held as a symmetry particle is (v_z >= 0 instead of = 0);
      // above it, a drift that would cross the plane ends on it: an impact, whose impulses J = m dv do the
      // work J (v_before + v_after) / 2 where the reactions' sum in step() books J v_half (the drift's).
      const double z = p.position_mm[s].z();
      if (drift_dt_ms > 0) {
        const double landing = -z / drift_dt_ms;
        if (z > kOnPlaneMm && v[s].z() < landing) {
          const double jump = landing - v[s].z();
          impact_work_correction_mJ_ -= 0.5 * p.mass_g[s] * jump * jump;
          landed_.push_back({static_cast<std::int32_t>(i), landing});
        }
        v[s].z() = std::max(v[s].z(), landing);
      } else if (z <= kOnPlaneMm) {
        v[s].z() = std::max(v[s].z(), 0.0);
      }
    } else if (f & kParticleSymmetry) v[s].z() = 0.0;
  }
  for (const VelocityConstraint& c : constraints_) {
    const double value = c.velocity_mm_per_ms(time_ms);
    for (size_t k = 0; k < c.particles.size(); ++k)
      v[static_cast<size_t>(c.particles[k])][c.axis] = c.scale.empty() ? value : value * c.scale[k];
  }
}

void TissueDynamics::half_kick(std::vector<Vec3d>& v, double dt) const {
  parallel_for(static_cast<std::int64_t>(v.size()), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) v[static_cast<size_t>(i)] += (0.5 * dt) * acceleration_[static_cast<size_t>(i)];
  });
}

double TissueDynamics::kinetic_energy_mJ() const {
  const TissueParticles& p = tissue_.particles();
  double ke = 0;
  for (std::int64_t i = 0; i < p.size(); ++i)
    ke += 0.5 * p.mass_g[static_cast<size_t>(i)] * p.velocity_mm_per_ms[static_cast<size_t>(i)].squaredNorm();
  return ke;
}

void TissueDynamics::set_external_forces(const std::vector<Vec3d>& force_N) {
  TissueParticles& p = tissue_.particles();
  NEEDLE_REQUIRE(force_N.size() == static_cast<size_t>(p.size()), "external forces need one force per particle");
  NEEDLE_REQUIRE(!drifted_, "external forces are set between steps, not inside one");
  external_force_ = force_N;
  for (std::int64_t i = 0; i < p.size(); ++i) {
    const size_t s = static_cast<size_t>(i);
    acceleration_[s] = (p.force_N[s] + external_force_[s]) / p.mass_g[s] + body_acceleration_;
  }
}

void TissueDynamics::set_mass_scaling(double target_dt_ms) {
  NEEDLE_REQUIRE(steps_ == 0 && !drifted_, "the tissue's mass scaling is set before the first step");
  mass_scaling_ = target_dt_ms > 0 ? std::make_unique<TissueMassScaling>(target_dt_ms, tissue_.particles()) : nullptr;
}

void TissueDynamics::retarget_mass_scaling(double target_dt_ms) {
  NEEDLE_REQUIRE(mass_scaling_ != nullptr, "the tissue's mass scaling is retargeted only where there is one");
  NEEDLE_REQUIRE(!drifted_, "the tissue's mass scaling is retargeted between steps");
  mass_scaling_->set_target_dt_ms(target_dt_ms);
}

void TissueDynamics::set_rate_levels(int max_level, double safety) {
  NEEDLE_REQUIRE(steps_ == 0 && !drifted_, "the tissue's rate levels are set before the first step");
  rate_levels_ = max_level > 0 ? std::make_unique<TissueRateLevels>(max_level, safety) : nullptr;
  if (!rate_levels_ && tissue_.multirate()) tissue_.set_rate_levels({});
}

void TissueDynamics::set_fast_particles(std::vector<std::uint8_t> fast) {
  NEEDLE_REQUIRE(rate_levels_ != nullptr, "particles are held fast only with rate levels");
  rate_levels_->set_fast_particles(std::move(fast));
}

double TissueDynamics::time_step_ms(double max_dt_ms) const {
  const double stable_dt = tissue_.stable_time_step_ms();
  const double first = steps_ == 0 ? stable_dt : first_dt_ms_;
  if (!(stable_dt > 1e-4 * first) || !std::isfinite(stable_dt))
    throw SolverError(fmt::format("the tissue's time step collapsed to {:.3g} ms (first step {:.3g} ms) at t = {:.6g} ms", stable_dt,
                                  first, time_ms_));
  // Within a cycle of the rate levels the base step may shrink, never grow: the slow points' periods hold.
  if (rate_levels_ && !at_rate_cycle_start()) max_dt_ms = std::min(max_dt_ms, cycle_dt_ms_);
  return std::min(mass_scaling_ ? mass_scaling_->time_step_ms(stable_dt) : stable_dt, max_dt_ms);
}

double TissueDynamics::kick_and_drift(double max_dt_ms) {
  NEEDLE_REQUIRE(!drifted_, "the tissue's step was not finished before the next");
  TissueParticles& p = tissue_.particles();
  const std::int64_t n = p.size();
  if (steps_ == 0) first_dt_ms_ = tissue_.stable_time_step_ms();
  const bool cycle_start = at_rate_cycle_start();
  const double dt = time_step_ms(max_dt_ms);
  step_dt_ms_ = dt;
  if (cycle_start) {
    // A new cycle of the rate levels: every point was just updated; the levels for this base step, and the
    // accelerations the step starts from with the new periods' weights.
    cycle_dt_ms_ = dt;
    tissue_.set_rate_levels(rate_levels_->levels(tissue_, dt));
    rate_levels_->record_point_levels(tissue_.point_levels());
    parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
      for (std::int64_t i = begin; i < end; ++i) {
        const size_t s = static_cast<size_t>(i);
        acceleration_[s] = (p.force_N[s] + external_force_[s]) / p.mass_g[s] + body_acceleration_;
      }
    });
  }
  if (rate_levels_) rate_levels_->count_step();
  if (mass_scaling_) {
    // Masses for this step's length; momentum kept, the kinetic energy's change booked apart.
    const double before = mass_scaling_->report().energy_mJ;
    for (std::int32_t i : mass_scaling_->apply(dt, tissue_, p, constrained_mask_)) {
      const size_t s = static_cast<size_t>(i);
      acceleration_[s] = (p.force_N[s] + external_force_[s]) / p.mass_g[s] + body_acceleration_;
    }
    energy_.mass_scaling_mJ += mass_scaling_->report().energy_mJ - before;
  }

  // Half kick, constraints, drift.
  for (size_t k = 0; k < constrained_.size(); ++k) constrained_velocity_before_[k] = p.velocity_mm_per_ms[static_cast<size_t>(constrained_[k])];
  std::vector<Vec3d>& v = p.velocity_mm_per_ms;
  half_kick(v, dt);
  apply_constraints(v, time_ms_ + 0.5 * dt, dt);
  for (size_t k = 0; k < constrained_.size(); ++k) constrained_velocity_half_[k] = p.velocity_mm_per_ms[static_cast<size_t>(constrained_[k])];
  old_force_.resize(static_cast<size_t>(n));
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) old_force_[static_cast<size_t>(i)] = p.force_N[static_cast<size_t>(i)] + external_force_[static_cast<size_t>(i)];
  });
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      displacement_[static_cast<size_t>(i)] = dt * p.velocity_mm_per_ms[static_cast<size_t>(i)];
      p.position_mm[static_cast<size_t>(i)] += displacement_[static_cast<size_t>(i)];
    }
  });
  time_ms_ += dt;
  drifted_ = true;
  return dt;
}

StepReport TissueDynamics::finish_step(const std::vector<Vec3d>* external_force_N) {
  NEEDLE_REQUIRE(drifted_, "finish_step needs kick_and_drift first");
  TissueParticles& p = tissue_.particles();
  const std::int64_t n = p.size();
  NEEDLE_REQUIRE(!external_force_N || external_force_N->size() == static_cast<size_t>(n), "external forces need one force per particle");
  drifted_ = false;
  const double dt = step_dt_ms_;
  const std::vector<Vec3d>& old_force = old_force_;
  const std::vector<Vec3d>& displacement = displacement_;
  StepReport report;
  report.dt_ms = dt;
  const ForceReport forces = tissue_.compute_forces(dt);
  report.bonds_broken_now = forces.bonds_broken_now;
  report.rate_factor_capped = forces.rate_factor_capped;
  report.particles_detached_now = forces.particles_detached_now;
  if (external_force_N) {
    old_external_force_.swap(external_force_);
    external_force_ = *external_force_N;
  } else {
    old_external_force_ = external_force_;
  }
  // old_force holds internal + external at the step's start; split the trapezoid sums accordingly. Each particle's
  // terms in parallel, their sums in particle order (the same bits for any thread count).
  work_terms_.resize(static_cast<size_t>(n));
  std::atomic<std::int64_t> non_finite{n};
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      if (!p.force_N[s].allFinite() || !external_force_[s].allFinite()) {
        std::int64_t first = non_finite.load();
        while (i < first && !non_finite.compare_exchange_weak(first, i)) {
        }
      }
      const Vec3d old_internal = old_force[s] - old_external_force_[s];
      work_terms_[s] = {0.5 * (old_internal + p.force_N[s]).dot(displacement[s]),
                        0.5 * (old_external_force_[s] + external_force_[s]).dot(displacement[s]),
                        p.mass_g[s] * body_acceleration_.dot(displacement[s])};
      acceleration_[s] = (p.force_N[s] + external_force_[s]) / p.mass_g[s] + body_acceleration_;
    }
  });
  if (non_finite.load() < n) throw SolverError(fmt::format("non-finite force on particle {} at t = {:.6g} ms", non_finite.load(), time_ms_));
  double model_work = 0, body_work = 0, external_work = 0;
  for (const std::array<double, 3>& terms : work_terms_) {
    model_work += terms[0];
    external_work += terms[1];
    body_work += terms[2];
  }
  // A particle an impulse moved between the halves: the first half's forces worked through the drift it
  // had before (velocity Verlet's own account of its kinetic energy), the second half's through the whole.
  for (const auto& [particle, shift] : impulse_shifts_) {
    const size_t s = static_cast<size_t>(particle);
    model_work -= 0.5 * (old_force[s] - old_external_force_[s]).dot(shift);
    external_work -= 0.5 * old_external_force_[s].dot(shift);
    body_work -= 0.5 * p.mass_g[s] * body_acceleration_.dot(shift);
  }
  impulse_shifts_.clear();
  energy_.model_work_mJ += model_work;
  energy_.body_work_mJ += body_work;
  energy_.external_work_mJ += external_work;
  std::vector<Vec3d>& v = p.velocity_mm_per_ms;
  half_kick(v, dt);
  apply_constraints(v, time_ms_, 0.0);
  // Reactions on constrained components: R = m dv/dt - f over the step, working through the displacement.
  double constraint_work = 0;
  for (size_t k = 0; k < constrained_.size(); ++k) {
    const size_t s = static_cast<size_t>(constrained_[k]);
    for (int axis = 0; axis < 3; ++axis) {
      if (!(constrained_mask_[s] & (1 << axis))) continue;
      constraint_work += p.mass_g[s] * (p.velocity_mm_per_ms[s][axis] - constrained_velocity_before_[k][axis]) *
                             constrained_velocity_half_[k][axis] -
                         0.5 * (old_force[s][axis] + p.force_N[s][axis] + external_force_[s][axis]) * displacement[s][axis];
    }
  }
  energy_.constraint_work_mJ += constraint_work + impact_work_correction_mJ_;
  impact_work_correction_mJ_ = 0;
  landed_.clear();
  energy_.kinetic_mJ = kinetic_energy_mJ();
  if (!std::isfinite(energy_.kinetic_mJ)) throw SolverError(fmt::format("kinetic energy is not finite at t = {:.6g} ms", time_ms_));
  tissue_.end_of_step();
  ++steps_;
  return report;
}

double TissueDynamics::apply_impulses(std::vector<std::pair<std::int32_t, Vec3d>>& impulses) {
  NEEDLE_REQUIRE(drifted_, "impulses act between kick_and_drift and finish_step");
  TissueParticles& p = tissue_.particles();
  const double dt = step_dt_ms_;
  double work = 0;
  for (auto& [particle, J] : impulses) {
    NEEDLE_REQUIRE(particle >= 0 && particle < p.size(), "an impulse on a particle that does not exist");
    const size_t s = static_cast<size_t>(particle);
    for (int axis = 0; axis < 3; ++axis)
      if (constrained_mask_[s] & (1 << axis)) J[axis] = 0;
    if (!J.isZero(0.0)) tissue_.check_may_move(particle);
    const Vec3d dv = J / p.mass_g[s];
    Vec3d& v = p.velocity_mm_per_ms[s];
    work += J.dot(v + 0.5 * dv);
    v += dv;
    displacement_[s] += dt * dv;
    p.position_mm[s] += dt * dv;
    impulse_shifts_.emplace_back(particle, dt * dv);
  }
  energy_.external_work_mJ += work;
  return work;
}

StepReport TissueDynamics::step(double max_dt_ms) {
  kick_and_drift(max_dt_ms);
  return finish_step(nullptr);
}

Eigen::Vector3d TissueDynamics::constraint_internal_force_N(size_t constraint) const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::int32_t i : constraints_.at(constraint).particles) sum += tissue_.particles().force_N[static_cast<size_t>(i)];
  return sum;
}

}  // namespace needle
