#pragma once
// The contact between the needle's surface and the tissue particles: what every contact law shares (the
// geometry: particles pulled back to the needle's reference configuration, the level set's signed distance and
// normal, the surface triangle under a point; the report, the contacts, the classification) and the interface
// the coupled step drives (begin_step, the needle's loads at its own steps, end_step). Two laws implement it,
// chosen by ContactOptions::law (contact_laws.h):
//   penalty    (penalty_contact.h): a frictional penalty force, integrated at the needle's (fine) step
//              inside the tissue's (coarse) step; its stiffness caps the coupling step;
//   projection (projection_contact.h): a kinematic contact that moves the particles out of the needle at the
//              end of each step and exchanges the impulse; it does not limit the step.
//
// The cost of cutting is a needle load of its own (cutting_resistance.h), not part of a contact law.
#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "solver/contact/contact_surface.h"
#include "solver/tissue/spg_tissue.h"
#include "solver/needle/needle_model.h"
#include "solver/tissue/tissue_dynamics.h"

namespace needle {

// A Coulomb coefficient between steel and soft tissue or gel: 0.05-0.5 measured; above this no scene means it
// (the scene reader and the --tissue-friction flag refuse it).
constexpr double kMaxFrictionCoefficient = 2.0;

struct ContactOptions {
  std::string law = "penalty";    // "penalty" or "projection" (contact_laws.h)
  double friction = 0.18;         // Coulomb coefficient needle-tissue (paper), at most kMaxFrictionCoefficient
  double stiffness_factor = 30.0; // penalty stiffness over the particle's own (penalty_contact.h); at 30 it lets no particle
                                  // deeper than 0.023 mm inside the needle over the paper's 30 mm (10: 0.07 mm; docs/notebook/paper_studies.md)
  double skin_mm = 0.02;          // contact starts this far outside the surface (projection: particles are put back this far out) (0.04 until the skin study showed AMB's
                                  // deflection converging only below 0.02 mm)
  double damping_ratio = 0.2;     // normal viscous damping, fraction of critical 2 sqrt(k m_r) (LS-DYNA's VDC)
  double needle_stiffness_scale = 0.1;  // cap of k on the needle's side, x m_c / dt_needle^2
  double voxel_mm = 0.02;         // the needle level set's resolution
  void validate(const std::string& where = "contact") const;  // InputError naming the bad field
  // The skin and stiffness in a run's one-line description (the paper report); empty at the defaults. (The law is
  // said with the needle model: runs/model_levels.h.)
  std::string describe() const;
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
  NeedleTissueContact(const ContactSurface& surface, const TissueParticles& particles, const ContactOptions& options);

  // The law's name, as ContactOptions::law spells it.
  virtual std::string law() const = 0;
  // The needle's nodal masses and its step (infinity for a rigid needle: no cap), before the first step.
  void set_needle(const Eigen::VectorXd& nodal_mass_g, double time_step_ms);
  // The longest coupling step the law allows, contact_courant being the fraction of its own stable step a
  // step may take (infinity: the law does not limit the step).
  virtual double max_time_step_ms(double contact_courant) const = 0;
  // Starts a tissue step from start_time_ms over dt_ms: the particles are at their end positions and
  // carry their mid-step velocities (after velocity Verlet's drift); the needle is at the step's start.
  virtual void begin_step(const TissueParticles& particles, const Eigen::MatrixX3d& needle_x_mm, const Eigen::MatrixX3d& needle_v_mm_per_ms,
                          double start_time_ms, double dt_ms) = 0;
  // Whether the needle's loads over the next step are set at this step's end (by end_step), whatever the particles
  // and the needle do before the next begin_step: then begin_step may be called ahead, with the next step's length,
  // from the state end_step left (the coupled insertion takes the needle's next span beside the tissue's work so).
  virtual bool needle_loads_set_at_step_end() const { return false; }
  // (NeedleLoads::needle_forces: the contact's forces on the needle at time_ms within the step.)
  // Ends the step, the needle at the step's end: the law acts on the tissue between its drift and its
  // second half (a kinematic law moves the particles through `tissue`) and writes the forces the tissue's
  // second half takes, one per particle (overwritten).
  virtual void end_step(TissueDynamics& tissue, const Eigen::MatrixX3d& needle_x_mm, const Eigen::MatrixX3d& needle_v_mm_per_ms,
                        std::vector<Vec3d>& particle_force) = 0;
  // The particles' forces of the last evaluation (the state at t = 0 before any step).
  virtual void last_particle_forces(std::vector<Vec3d>& particle_force) const = 0;

  // The state of the last force evaluation (in contact, forces per facet, energy) and of the last
  // step's penetration check.
  const ContactReport& report() const { return report_; }
  // Energy dissipated by the contact (friction, damping, inelastic impact) since the start.
  double friction_dissipation_mJ() const { return friction_dissipation_mJ_; }
  // Energy the law's discretisation adds (> 0) or removes, outside the balance: a diagnostic (penalty_contact.h).
  double relinearisation_energy_mJ() const { return relinearisation_energy_mJ_; }
  // Classifies every particle against the needle at the given state (level set; no forces).
  InsideReport classify(const TissueParticles& particles, const Eigen::MatrixX3d& needle_x_mm);

  // Per particle: 1 if in contact at the last step's end.
  std::vector<std::uint8_t> in_contact() const;
  // The contacts at the last step's end (or at t = 0): particle and surface triangle (-1: a node fallback).
  const std::vector<std::pair<int, int>>& contacts() const { return contacts_; }
  // Points pulled back to the needle's reference configuration by the displacement of the nearest
  // surface node (as the contact does); NaN where no surface node lies within the search radius.
  std::vector<Eigen::Vector3d> pull_back(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x);
  const ContactSurface& surface() const { return surface_; }
  const ContactOptions& options() const { return options_; }

 protected:
  // A particle that may touch the needle during the step, with the geometry found at the step's start.
  struct Pair {
    int particle = -1;
    int triangle = -1, node = -1;  // node: fallback when no triangle lies under the point
    Eigen::Vector3d weights = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::UnitX();
    Eigen::Vector3d particle_start = Eigen::Vector3d::Zero(), particle_velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d surface_start = Eigen::Vector3d::Zero();  // the needle's surface point at the start
    double gap_start = 0;                                      // skin - phi at the start
    double stiffness = 0, damping = 0, friction_cap = 0;       // the penalty law's constants over the step
  };
  struct Probe {  // one particle's geometric query
    int index = -1;  // the position's index in the probed list
    bool near = false, inside = false;
    double phi = 0;
    Pair pair;
  };
  // Level-set query of every particle at positions x (reach: how far outside the skin still counts as near).
  // same_needle: the needle has not moved since the last probe, whose grid of surface nodes serves again.
  // The probes go to `out` (default: probes_), in increasing index, one for each position whose signed distance
  // was looked up: the others (far outside the needle's box, or with no surface node near) are neither near
  // nor inside, and have no probe.
  void probe(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x, const std::vector<double>& reach, bool same_needle = false,
             std::vector<Probe>* out = nullptr);
  Eigen::Vector3d surface_point(const Pair& pair, const Eigen::MatrixX3d& needle) const;
  // The needle's mass at a pair's contact point, by the force's weights (infinity without masses).
  double needle_mass_at(const Pair& pair) const;
  // Adds a force on the needle at a pair's contact point to the nodal forces and books it on its facet.
  void book_needle_force(const Pair& pair, const Eigen::Vector3d& force_on_needle, double normal_N, double friction_N, NodalForces& out);
  void clear_report_forces();

  const ContactSurface& surface_;
  ContactOptions options_;
  std::vector<double> mass_;
  Eigen::VectorXd needle_mass_;
  double needle_dt_ms_ = std::numeric_limits<double>::infinity();
  std::vector<Probe> probes_;
  std::vector<std::pair<int, int>> contacts_;  // (particle, triangle) in contact at the last step's end
  double friction_dissipation_mJ_ = 0, relinearisation_energy_mJ_ = 0;
  ContactReport report_;

 private:
  void build_node_grid(const Eigen::MatrixX3d& needle_x);
  int nearest_surface_node(const Eigen::Vector3d& p) const;  // in the grid of the last build_node_grid

  // Grid of the current surface nodes (rebuilt when the needle moves): cells of node_cell_mm_ (the search's
  // radius) from node_origin_, each cell's nodes in increasing order, with their positions beside them.
  double node_cell_mm_ = 0;
  Eigen::Vector3d node_origin_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i node_grid_dims_ = Eigen::Vector3i::Zero();
  std::vector<int> node_cell_start_;  // cell c's surface nodes: node_cell_nodes_[start[c] .. start[c + 1])
  std::vector<int> node_cell_nodes_;
  std::vector<Eigen::Vector3d> node_cell_points_;  // their positions, in the same order
  Eigen::Vector3d box_lo_ = Eigen::Vector3d::Zero(), box_hi_ = Eigen::Vector3d::Zero();
};

}  // namespace needle
