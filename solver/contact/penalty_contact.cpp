#include "solver/contact/penalty_contact.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"
#include "core/parallel.h"

namespace needle {

PenaltyContact::PenaltyContact(const ContactSurface& surface, const TissueParticles& particles, const TissueMaterial& material,
                               const ContactOptions& options)
    : NeedleTissueContact(surface, particles, options) {
  const size_t n = static_cast<size_t>(particles.size());
  stiffness_.resize(n);
  stable_dt_ms_ = std::numeric_limits<double>::infinity();
  // The penalty follows the tissue at a strain the needle imposes (1): the elastic modulus for the
  // paper's card, the stiffened tangent for a stiffening law.
  const double modulus = material.tangent_p_wave_modulus_MPa(1.0);
  for (size_t i = 0; i < n; ++i) {
    const double h = particles.spacing_mm[i];
    stiffness_[i] = options_.stiffness_factor * modulus * particles.reference_volume_mm3[i] / (h * h);
    stable_dt_ms_ = std::min(stable_dt_ms_, 2 * std::sqrt(mass_[i] / stiffness_[i]));
  }
}

void PenaltyContact::begin_step(const TissueParticles& particles, const Eigen::MatrixX3d& needle_x, const Eigen::MatrixX3d& needle_v,
                                double start_time_ms, double dt_ms) {
  NEEDLE_REQUIRE(dt_ms > 0, "contact: a step needs a positive length");
  const size_t n = static_cast<size_t>(particles.size());
  double needle_speed = 0;
  for (int node : surface_.nodes()) needle_speed = std::max(needle_speed, needle_v.row(node).norm());
  std::vector<Vec3d> start(n);
  std::vector<double> reach(n);
  parallel_for(static_cast<std::int64_t>(n), [&](std::int64_t begin, std::int64_t end) {
    for (size_t i = static_cast<size_t>(begin); i < static_cast<size_t>(end); ++i) {
      const Vec3d& v = particles.velocity_mm_per_ms[i];
      start[i] = particles.position_mm[i] - dt_ms * v;
      // Whatever can close the gap within the step, with room to spare.
      reach[i] = 1.5 * dt_ms * (v.norm() + needle_speed) + 0.25 * options_.skin_mm;
    }
  });
  probe(start, needle_x, reach);
  pairs_.clear();
  report_.particles_inside = 0;
  report_.max_depth_mm = 0;
  for (const Probe& p : probes_) {
    const size_t i = static_cast<size_t>(p.index);
    if (p.inside) {
      ++report_.particles_inside;
      report_.max_depth_mm = std::max(report_.max_depth_mm, -p.phi);
    }
    if (!p.near) continue;
    Pair& pair = pairs_.emplace_back(p.pair);
    pair.particle_velocity = particles.velocity_mm_per_ms[i];
    // The law's constants over the step. The needle's mass at the contact point, by the force's weights,
    // caps the stiffness on its side and enters the damper's reduced mass and the friction cap.
    const double needle_mass = needle_mass_at(pair);
    const bool rigid = !std::isfinite(needle_dt_ms_);
    pair.stiffness = rigid ? stiffness_[i]
                           : std::min(stiffness_[i], options_.needle_stiffness_scale * needle_mass / (needle_dt_ms_ * needle_dt_ms_));
    const double reduced_mass = std::isfinite(needle_mass) ? mass_[i] * needle_mass / (mass_[i] + needle_mass) : mass_[i];
    pair.damping = options_.damping_ratio * 2 * std::sqrt(pair.stiffness * reduced_mass);
    // The viscous cap: friction may not reverse the sliding within either body's step.
    pair.friction_cap = 0.5 * std::min(mass_[i] / dt_ms, rigid ? mass_[i] / dt_ms : needle_mass / needle_dt_ms_);
  }
  // The penalty energy jumps where the geometry is found anew (the gap was linearised over the last step).
  double penalty_now = 0;
  for (const Pair& pair : pairs_)
    if (pair.gap_start > 0) penalty_now += 0.5 * pair.stiffness * pair.gap_start * pair.gap_start;
  if (start_time_ms > 0) relinearisation_energy_mJ_ += penalty_now - report_.penalty_energy_mJ;
  pair_force_.assign(pairs_.size(), Eigen::Vector3d::Zero());
  pair_elastic_force_.assign(pairs_.size(), Eigen::Vector3d::Zero());
  pair_dissipative_impulse_.assign(pairs_.size(), Eigen::Vector3d::Zero());
  step_start_ms_ = start_time_ms;
  step_dt_ms_ = dt_ms;
  last_eval_ms_ = std::max(last_eval_ms_, start_time_ms);
}

void PenaltyContact::needle_forces(const Eigen::MatrixX3d& needle_x, const Eigen::MatrixX3d& needle_v, double time_ms, NodalForces& out) {
  const double tau = time_ms - step_start_ms_, dt = time_ms - last_eval_ms_;
  const double mu = options_.friction;
  clear_report_forces();
  double friction_power = 0;
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const Pair& pair = pairs_[k];
    Eigen::Vector3d& f = pair_force_[k];
    Eigen::Vector3d& f_elastic = pair_elastic_force_[k];
    f.setZero();
    f_elastic.setZero();
    const Eigen::Vector3d surface_now = surface_point(pair, needle_x);
    const double gap = pair.gap_start - pair.normal.dot(tau * pair.particle_velocity - (surface_now - pair.surface_start));
    if (gap <= 0) continue;
    const double kn = pair.stiffness;
    const Eigen::Vector3d v_rel = pair.particle_velocity - surface_point(pair, needle_v);
    const double approach = v_rel.dot(pair.normal);  // > 0: separating
    const double fn = std::max(0.0, kn * gap - pair.damping * approach);
    friction_power -= (fn - kn * gap) * approach;  // the damper's share: -f_d . v_n >= 0
    f = fn * pair.normal;
    f_elastic = kn * gap * pair.normal;
    const Eigen::Vector3d v_t = v_rel - v_rel.dot(pair.normal) * pair.normal;
    const double speed = v_t.norm();
    double ft = 0;
    if (speed > 0 && mu > 0) {
      ft = std::min(mu * fn, pair.friction_cap * speed);
      f -= ft * v_t / speed;
    }
    friction_power += ft * speed;
    // The dissipative part (damper and friction) as the needle receives it over its substep.
    if (dt > 0) pair_dissipative_impulse_[k] += dt * (f - f_elastic);
    book_needle_force(pair, -f, fn, ft, out);
    report_.penalty_energy_mJ += 0.5 * kn * gap * gap;
  }
  report_.cutting_force_N = 0;
  report_.friction_power_mW = friction_power;
  if (dt > 0) friction_dissipation_mJ_ += 0.5 * dt * (last_friction_power_mW_ + friction_power);
  if (tau == 0) {  // the state at a step's start (t = 0, before any step): the particles get the forces as they are
    previous_force_.clear();
    previous_particles_.clear();
    for (size_t k = 0; k < pairs_.size(); ++k)
      if (pair_force_[k].squaredNorm() > 0) {
        previous_force_.push_back(pair_force_[k]);
        previous_particles_.push_back(pairs_[k].particle);
      }
    record_contacts();
  }
  last_friction_power_mW_ = friction_power;
  last_eval_ms_ = time_ms;
}

void PenaltyContact::end_step(TissueDynamics&, const Eigen::MatrixX3d&, const Eigen::MatrixX3d&, std::vector<Vec3d>& particle_force) {
  end_step(particle_force);
}

void PenaltyContact::end_step(std::vector<Vec3d>& particle_force) {
  NEEDLE_REQUIRE(last_eval_ms_ >= step_start_ms_ + step_dt_ms_ - 1e-9 * std::max(step_dt_ms_, std::abs(step_start_ms_)),
                 fmt::format("contact: the step ended at {} ms before the needle reached its end {} + {} ms", last_eval_ms_, step_start_ms_,
                             step_dt_ms_));
  // The particles get the penalty at the step's end and the dissipative forces as the needle received
  // them over the step (their mean): friction follows the needle's vibration within the step, which one
  // sample at the end would alias. The elastic part must not lag (see the header); the dissipative part may.
  previous_force_.clear();
  previous_particles_.clear();
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const Eigen::Vector3d f = pair_elastic_force_[k] + pair_dissipative_impulse_[k] / step_dt_ms_;
    if (f.squaredNorm() == 0) continue;
    previous_force_.push_back(f);
    previous_particles_.push_back(pairs_[k].particle);
  }
  record_contacts();
  last_particle_forces(particle_force);
}

void PenaltyContact::record_contacts() {
  contacts_.clear();
  for (size_t k = 0; k < pairs_.size(); ++k)
    if (pair_force_[k].squaredNorm() > 0) contacts_.emplace_back(pairs_[k].particle, pairs_[k].triangle);
}

void PenaltyContact::last_particle_forces(std::vector<Vec3d>& particle_force) const {
  particle_force.assign(stiffness_.size(), Vec3d::Zero());
  for (size_t k = 0; k < previous_force_.size(); ++k) particle_force[static_cast<size_t>(previous_particles_[k])] = previous_force_[k];
}

}  // namespace needle
