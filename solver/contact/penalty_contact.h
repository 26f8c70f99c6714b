#pragma once
// The frictional penalty contact (needle_tissue_contact.h has what every contact law shares).
//
// The penalty law, for a particle at p pulled back to the needle's reference configuration X (ContactSurface::pull_back)
// (contact_surface.h), with signed distance phi(X) to the needle surface:
//   gap g = skin - phi > 0 means contact (the skin keeps particles off the true surface);
//   normal   f_n = k_i g n,   k_i = stiffness_factor * M * V_i / h_i^2  (M the tissue's P-wave modulus,
//            V_i, h_i the particle's volume and spacing: a multiple of the particle's own stiffness);
//   k is capped on the needle's side at needle_stiffness_scale m_c / dt_needle^2 (m_c the needle's mass at
//   the contact point, from its nodes by the same weights), so that a light node at the tip is never made
//   unstable at the needle's step (as LS-DYNA's SOFT=1 contact does);
//   damping  f_d = -zeta 2 sqrt(k m_r) (v_rel . n) n, m_r the reduced mass of particle and contact point, while in contact and as long as f_n + f_d pushes;
//            it damps the contact's own oscillation, which the two clocks would otherwise feed;
//   friction f_t = -min(mu f_n, c_i |v_t|) v_t / |v_t|,  v_t the particle's tangential velocity relative
//            to the needle's surface point, c = min(m_i / Dt, m_c / dt_needle) / 2 (a viscous cap that
//            regularises sticking and never reverses the sliding within either body's step);
//   n is the level set's outward normal, turned with the current surface triangle under the point.
// The particle gets f = f_n + f_t; the needle gets -f on the three nodes of that triangle by
// barycentric weights. Forces are booked per facet tag (top, bottom, sides, lancets, groove floor ...).
//
// The cost of cutting is a needle load of its own (cutting_resistance.h), not part of this law.
//
// Multi-rate integration over one tissue step [t, t + Dt] (insertion/coupled_insertion.h):
//   begin_step: the particles move on straight lines over the step (velocity Verlet's drift), so their
//     path is known. The geometry (triangle, weights, normal, phi) is found once, at t, for every particle
//     that can reach the surface within the step;
//   needle_forces: at each of the needle's substeps the gap is updated linearly from both bodies' motion
//     since t, g = g(t) - n . (dx_particle - dx_surface point), and the forces go to the needle;
//   end_step: the particles receive the last evaluation's forces, i.e. the contact at t + Dt with both
//     bodies at their new positions: for the particles this is plain velocity Verlet with the contact as
//     one more force (stable below the contact's own step limit, which caps Dt).
// Each side integrates the same force history with its own velocity Verlet, so energy is consistent on
// both; the momentum the two receive differs only by the curvature of the force within one step (the
// needle integrates the substep history, the particles the trapezoid of its end values). Measured in
// the tests. (Giving the particles the step's mean force instead would exchange momentum exactly, but
// it evaluates the penalty half a step late for them, which pumps energy in: tried and rejected.)
#include <vector>

#include "solver/contact/needle_tissue_contact.h"

namespace needle {

class PenaltyContact : public NeedleTissueContact {
 public:
  PenaltyContact(const ContactSurface& surface, const TissueParticles& particles, const TissueMaterial& material,
                 const ContactOptions& options);

  std::string law() const override { return "penalty"; }
  // contact_courant times the contact's own stable step.
  double max_time_step_ms(double contact_courant) const override { return contact_courant * stable_dt_ms_; }
  void begin_step(const TissueParticles& particles, const Eigen::MatrixX3d& needle_x_mm, const Eigen::MatrixX3d& needle_v_mm_per_ms,
                  double start_time_ms, double dt_ms) override;
  void needle_forces(const Eigen::MatrixX3d& needle_x_mm, const Eigen::MatrixX3d& needle_v_mm_per_ms, double time_ms,
                     NodalForces& force_N) override;
  // The particles' forces at the step's end; the tissue is left to take them in its second half.
  void end_step(TissueDynamics& tissue, const Eigen::MatrixX3d& needle_x_mm, const Eigen::MatrixX3d& needle_v_mm_per_ms,
                std::vector<Vec3d>& particle_force) override;
  // The same, on its own: particle_force (one per particle, overwritten) is the contact at the step's end.
  void end_step(std::vector<Vec3d>& particle_force);
  void last_particle_forces(std::vector<Vec3d>& particle_force) const override;

  // The contact's own stable step for a particle alone: min over particles of 2 sqrt(m_i / k_i).
  double stable_time_step_ms() const { return stable_dt_ms_; }

 private:
  void record_contacts();  // contacts_ from the last evaluation (at a step's end, not at every substep)

  std::vector<double> stiffness_;
  double stable_dt_ms_ = 0;
  std::vector<Pair> pairs_;
  std::vector<Eigen::Vector3d> pair_force_;                   // per pair, at the current evaluation
  std::vector<Eigen::Vector3d> pair_elastic_force_;           // per pair, the penalty part of pair_force_
  std::vector<Eigen::Vector3d> pair_dissipative_impulse_;     // per pair, damper + friction integrated over the step
  std::vector<Eigen::Vector3d> previous_force_;               // the particles' forces of the last step's end ...
  std::vector<int> previous_particles_;                       // ... and their particles
  double step_start_ms_ = 0, step_dt_ms_ = 0, last_eval_ms_ = 0, last_friction_power_mW_ = 0;
};

}  // namespace needle
