#pragma once
// Frictional penalty contact between the needle's surface and the tissue particles, integrated at the
// needle's (fine) step inside the tissue's (coarse) step.
//
// Contact law, for a particle at p pulled back to the needle's reference configuration X (ContactSurface::pull_back)
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
#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "solver/contact/contact_surface.h"
#include "solver/tissue/spg_tissue.h"
#include "solver/needle/needle_model.h"

namespace needle {

struct ContactOptions {
  double friction = 0.18;         // Coulomb coefficient needle-tissue (paper)
  double stiffness_factor = 30.0; // penalty stiffness over the particle's own (see above); at 30 it lets no particle
                                  // deeper than 0.023 mm inside the needle over the paper's 30 mm (10: 0.07 mm; docs/notebook/paper_studies.md)
  double skin_mm = 0.02;          // contact starts this far outside the surface (0.04 until the skin study showed AMB's
                                  // deflection converging only below 0.02 mm)
  double damping_ratio = 0.2;     // normal viscous damping, fraction of critical 2 sqrt(k m_r) (LS-DYNA's VDC)
  double needle_stiffness_scale = 0.1;  // cap of k on the needle's side, x m_c / dt_needle^2
  double voxel_mm = 0.02;         // the needle level set's resolution
  void validate(const std::string& where = "contact") const;  // InputError naming the bad field
};

// Force on the needle booked on one facet tag.
struct FacetContact {
  int particles = 0;
  double normal_N = 0;    // sum of |f_n|
  double friction_N = 0;  // sum of |f_t|
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();  // total force on the needle
  Eigen::Vector3d cutting_force_N = Eigen::Vector3d::Zero();  // the cutting resistance's share of it
};

struct ContactReport {
  int particles_in_contact = 0;
  int particles_inside = 0;          // particles whose pulled-back point lies inside the needle (phi < 0)
  double max_depth_mm = 0;           // deepest such point below the true surface
  double penalty_energy_mJ = 0;      // sum 1/2 k g^2
  double friction_power_mW = 0;      // rate of dissipation by friction and normal damping (>= 0)
  double cutting_force_N = 0;        // the cutting resistance's magnitude, sum of p_c A over the loaded triangles
  Eigen::Vector3d force_on_needle_N = Eigen::Vector3d::Zero();
  std::vector<FacetContact> facets;  // indexed like ContactSurface::tag_names()
};

// Which particles lie inside the needle (signed distance < 0 at their pulled-back point).
struct InsideReport {
  int particles_inside = 0;
  double max_depth_mm = 0;
};

class NeedleTissueContact : public NeedleLoads {
 public:
  NeedleTissueContact(const ContactSurface& surface, const TissueParticles& particles, const TissueMaterial& material,
                      const ContactOptions& options);

  // The needle's nodal masses and its step (infinity for a rigid needle: no cap), before the first step.
  void set_needle(const Eigen::VectorXd& nodal_mass_g, double time_step_ms);
  // Starts a tissue step from start_time_ms over dt_ms: the particles are at their end positions and
  // carry their mid-step velocities (after velocity Verlet's drift); the needle is at the step's start.
  void begin_step(const TissueParticles& particles, const Eigen::MatrixX3d& needle_x_mm, const Eigen::MatrixX3d& needle_v_mm_per_ms,
                  double start_time_ms, double dt_ms);
  // The contact forces on the needle at time_ms within the step (NeedleLoads).
  void needle_forces(const Eigen::MatrixX3d& needle_x_mm, const Eigen::MatrixX3d& needle_v_mm_per_ms, double time_ms,
                     NodalForces& force_N) override;
  // Ends the step: particle_force (one per particle, overwritten) is the contact at the step's end.
  void end_step(std::vector<Vec3d>& particle_force);
  // The particles' forces of the last evaluation (the state at t = 0 before any step).
  void last_particle_forces(std::vector<Vec3d>& particle_force) const;

  // The state of the last force evaluation (in contact, forces per facet, energy) and of the last
  // begin_step (particles inside).
  const ContactReport& report() const { return report_; }
  // Energy dissipated by friction and normal damping since the start.
  double friction_dissipation_mJ() const { return friction_dissipation_mJ_; }
  // Sum of the penalty energy's jumps where each step finds the geometry anew (the gap is linearised
  // within a step): energy the contact's discretisation adds (> 0) or removes. A diagnostic.
  double relinearisation_energy_mJ() const { return relinearisation_energy_mJ_; }
  // Classifies every particle against the needle at the given state (level set; no forces).
  InsideReport classify(const TissueParticles& particles, const Eigen::MatrixX3d& needle_x_mm);

  // The contact's own stable step for a particle alone: min over particles of 2 sqrt(m_i / k_i).
  double stable_time_step_ms() const { return stable_dt_ms_; }
  // Per particle: 1 if in contact at the last step's end.
  std::vector<std::uint8_t> in_contact() const;
  // The contacts at the last step's end (or at t = 0): particle and surface triangle (-1: a node fallback).
  const std::vector<std::pair<int, int>>& contacts() const { return contacts_; }
  // Points pulled back to the needle's reference configuration by the displacement of the nearest
  // surface node (as the contact does); NaN where no surface node lies within the search radius.
  std::vector<Eigen::Vector3d> pull_back(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x);
  const ContactSurface& surface() const { return surface_; }
  const ContactOptions& options() const { return options_; }

 private:
  // A particle that may touch the needle during the step, with the geometry found at the step's start.
  struct Pair {
    int particle = -1;
    int triangle = -1, node = -1;  // node: fallback when no triangle lies under the point
    Eigen::Vector3d weights = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitX();
    Eigen::Vector3d particle_start = Eigen::Vector3d::Zero(), particle_velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d surface_start = Eigen::Vector3d::Zero();  // the needle's surface point at the start
    double gap_start = 0;                                      // skin - phi at the start
    double stiffness = 0, damping = 0, friction_cap = 0;       // the law's constants over the step
  };
  struct Probe {  // one particle's geometric query
    bool near = false, inside = false;
    double phi = 0;
    Pair pair;
  };
  void build_node_grid(const Eigen::MatrixX3d& needle_x);
  int nearest_surface_node(const Eigen::Vector3d& p, const Eigen::MatrixX3d& needle_x) const;
  // Level-set query of every particle at positions x (reach: how far outside the skin still counts as near).
  void probe(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x, const std::vector<double>& reach);
  Eigen::Vector3d surface_point(const Pair& pair, const Eigen::MatrixX3d& needle) const;
  void record_contacts();  // contacts_ from the last evaluation (at a step's end, not at every substep)

  const ContactSurface& surface_;
  ContactOptions options_;
  std::vector<double> stiffness_, mass_;
  Eigen::VectorXd needle_mass_;
  double needle_dt_ms_ = std::numeric_limits<double>::infinity();
  double stable_dt_ms_ = 0;
  std::vector<Probe> probes_;
  std::vector<Pair> pairs_;
  std::vector<Eigen::Vector3d> pair_force_;                   // per pair, at the current evaluation
  std::vector<Eigen::Vector3d> pair_elastic_force_;           // per pair, the penalty part of pair_force_
  std::vector<Eigen::Vector3d> pair_dissipative_impulse_;     // per pair, damper + friction integrated over the step
  std::vector<Eigen::Vector3d> previous_force_;               // the particles' forces of the last step's end ...
  std::vector<int> previous_particles_;                       // ... and their particles
  std::vector<std::pair<int, int>> contacts_;                 // (particle, triangle) in contact at the last step's end
  double step_start_ms_ = 0, step_dt_ms_ = 0, last_eval_ms_ = 0, last_friction_power_mW_ = 0, friction_dissipation_mJ_ = 0, relinearisation_energy_mJ_ = 0;
  ContactReport report_;
  // Grid of the current surface nodes (rebuilt per query): sorted (cell, node).
  double node_cell_mm_ = 0;
  Eigen::Vector3d node_origin_ = Eigen::Vector3d::Zero();
  std::vector<std::pair<long, int>> node_cells_;
  Eigen::Vector3d box_lo_ = Eigen::Vector3d::Zero(), box_hi_ = Eigen::Vector3d::Zero();
};

}  // namespace needle
