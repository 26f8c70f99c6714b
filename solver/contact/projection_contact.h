#pragma once
// A kinematic contact: the needle's steel is about 10^6 times stiffer than the gel, so the particles are
// put back outside the needle at the end of each tissue step instead of being pushed out by a penalty
// spring whose stiffness would set the step (penalty_contact.h). It never limits the coupling step, which
// then is the tissue's own stable step. needle_tissue_contact.h has what the laws share.
//
// At the end of a step [t, t + dt], the needle at t + dt (it moved first, under the last step's reaction),
// the particles after velocity Verlet's drift (end positions x, mid-step velocities v):
//   each particle whose pulled-back point lies within the skin, phi < skin, with the level set's outward
//   normal n (turned with the surface triangle under it), receives the normal impulse
//     J_n = m (skin - phi) / dt n:  through the drift it ends on the skin, phi = skin (to first order);
//   friction: v_t the particle's tangential velocity after J_n relative to the needle's surface point at
//     t + dt; J_t = -min(mu |J_n|, m |v_t|) v_t / |v_t|: Coulomb, and never more than stops the sliding;
//   J = J_n + J_t acts on the tissue between its halves (TissueDynamics::apply_impulses: v += J/m,
//   x += dt J/m), components its constraints hold dropped.
// The needle receives -J on the three nodes of the triangle under the point, by barycentric weights, as a
// constant force -J / dt' over the next step dt': momentum is exchanged exactly, one step late (the lag
// never accumulates). The lag is stable: within one tissue step the needle's bending responds to a force
// F by F dt^2 / (2 m) with m its modal mass, about 0.1 g, which against the particles' m_p / dt^2 gives a loop
// gain of order 0.1 at the paper's resolution.
// Energy: the contact stores none; the impulses' work on the particles (exact) and on the needle (the
// reaction times its surface points' displacement over the step it acts in) is booked as dissipation,
// D = -(W_particles + W_needle), which an inelastic contact keeps >= 0 (the coupled run's balance holds it
// beside the bodies' own accounts; a negative D is energy the lag created and shows in the report).
// Penetration: after the impulses, each moved particle is classified again; the report's particles_inside
// and max_depth_mm are that check (the skin's first-order projection leaves them at 0 on smooth facets).
#include <vector>

#include "solver/contact/needle_tissue_contact.h"

namespace needle {

class ProjectionContact : public NeedleTissueContact {
 public:
  ProjectionContact(const ContactSurface& surface, const TissueParticles& particles, const ContactOptions& options);

  std::string law() const override { return "projection"; }
  double max_time_step_ms(double) const override { return std::numeric_limits<double>::infinity(); }
  // The last step's reaction becomes the needle's load over this step.
  void begin_step(const TissueParticles& particles, const Eigen::MatrixX3d& needle_x_mm, const Eigen::MatrixX3d& needle_v_mm_per_ms,
                  double start_time_ms, double dt_ms) override;
  // Yes: the reaction end_step found, over the next step's length.
  bool needle_loads_set_at_step_end() const override { return true; }
  // The reaction, constant over the step.
  void needle_forces(const Eigen::MatrixX3d& needle_x_mm, const Eigen::MatrixX3d& needle_v_mm_per_ms, double time_ms,
                     NodalForces& force_N) override;
  // The impulses at the step's end (see above); particle_force is all zero (the contact acted already).
  void end_step(TissueDynamics& tissue, const Eigen::MatrixX3d& needle_x_mm, const Eigen::MatrixX3d& needle_v_mm_per_ms,
                std::vector<Vec3d>& particle_force) override;
  void last_particle_forces(std::vector<Vec3d>& particle_force) const override;

  // The impulse the needle has still to receive (g mm/ms): the last step's, applied over the next.
  Eigen::Vector3d pending_impulse() const;
  // The work of the impulses on the particles and on the needle since the start (mJ).
  double particle_work_mJ() const { return particle_work_mJ_; }
  double needle_work_mJ() const { return needle_work_mJ_; }

 private:
  struct Reaction {  // one particle's impulse on the needle, at a surface point
    Pair pair;
    Eigen::Vector3d impulse = Eigen::Vector3d::Zero();  // on the needle
    Eigen::Vector3d point_start = Eigen::Vector3d::Zero();
  };
  std::vector<Reaction> pending_;  // from the last step's end, acting over the current step
  NodalForces pending_force_;      // pending_ as nodal forces over the current step, one entry per node
  std::vector<Probe> check_probes_;  // the moved particles' probes after the impulses (probes_ keeps all particles')
  double step_dt_ms_ = 0, particle_work_mJ_ = 0, needle_work_mJ_ = 0;
};

}  // namespace needle
