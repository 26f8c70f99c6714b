#pragma once
// The L-SPG insertion: the Lagrangian FE needle (needle_dynamics.h) driven into the SPG tissue
// (spg_tissue.h, explicit_dynamics.h) through frictional penalty contact (needle_tissue_contact.h),
// in one explicit run with two time steps.
//
// The steel's stable step is hundreds of times the tissue's smaller, so the needle subcycles:
// one coupling step of the tissue's size Dt is
//   1. the needle takes its own steps from t to t + Dt under the contact force -C(t), held constant;
//   2. the tissue takes one velocity-Verlet step of Dt; after its drift the contact C(t + Dt) is computed
//      from both bodies' new positions and acts on the particles at once (so the tissue's side of the
//      stiff penalty is integrated exactly as a force of its own) and on the needle from the next step;
//   3. the bonds the needle's body now passes through are cut (needle_bond_cut.h; ContactOptions::cuts_bonds),
//      as the failure criterion breaks its bonds after a force evaluation: from the next step on; with a
//      slit (symmetry_slit.h; ContactOptions::slit), the symmetry particles behind the tip are opened; with a
//      crack (tip_crack.h; ContactOptions::crack), the bonds across its fins at the tip are cut too.
// Each step, the needle receives -C(t) Dt and the tissue (C(t) + C(t + Dt)) Dt / 2: momentum is exchanged
// exactly up to a half-step lag that never accumulates (it telescopes to Dt/2 |C(end) - C(0)|). The lag is
// stable because the steel's response to a force within one tissue step is tiny next to the contact's
// own stiffness (the loop gain is k_contact / K_steel, about 1e-3). With subcycling off, both bodies take
// the needle's step: the plain full model the subcycled one is measured against (bench_insertion).
//
// Energy: the bodies' balances hold on their own; the run's physical balance is
//   W_drive + W_cannula = dKE + dU_needle + E_tissue (stored + plastic, -W_model) + E_penalty + D_friction,
// with E_penalty and D_friction from the contact law, not from the forces' work, so a contact that
// creates or destroys energy (lag, sticking) shows up as balance error. The run stops with a
// SolverError (never NaN) on non-finite state, runaway penetration, time-step collapse, or drift.
#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "solver/explicit_dynamics.h"
#include "solver/needle_dynamics.h"
#include "solver/needle_bond_cut.h"
#include "solver/needle_tissue_contact.h"
#include "solver/symmetry_slit.h"
#include "solver/tip_crack.h"

namespace needle {

struct CouplingOptions {
  bool subcycling = true;       // false: the tissue takes the needle's step (plain full model)
  double max_step_ms = 0.0;     // cap on the coupling step (0: the tissue's and the contact's limits only)
  double contact_courant = 0.1; // fraction of the contact's own stable step (2 sqrt(m/k)) a coupling step may
                                // take: the accuracy knob of the subcycling (its error is first order in it)
  double max_energy_error = 0.05;    // stop when the physical balance drifts beyond this (once the work from outside exceeds the energy at t = 0)
  double max_depth_mm = 0.3;         // stop when a particle gets this deep inside the needle
  Eigen::Vector3d tissue_body_acceleration_mm_per_ms2 = Eigen::Vector3d::Zero();  // e.g. to press a block on
  void validate(const std::string& where = "coupling") const;
};

struct InsertionEnergy {
  double tissue_kinetic_mJ = 0, tissue_internal_mJ = 0;  // internal: stored + plastically dissipated (-W_model)
  double needle_kinetic_mJ = 0, needle_strain_mJ = 0, needle_initial_mJ = 0, tissue_initial_kinetic_mJ = 0;
  double drive_work_mJ = 0, cannula_work_mJ = 0, tissue_reaction_work_mJ = 0, body_work_mJ = 0;
  double contact_work_mJ = 0;  // work of the contact forces on both bodies (should equal -(E_penalty + D_friction))
  double relinearisation_energy_mJ = 0;  // the contact's penalty jumps at geometry updates (diagnostic, not in the balance)
  double penalty_energy_mJ = 0, initial_penalty_energy_mJ = 0, friction_dissipation_mJ = 0;  // initial: overlaps at t = 0
  // |inputs - stored - dissipated| / the largest term (the energy at t = 0 among them)
  double balance_error() const;
  double initial_energy_mJ() const;  // kinetic, strain and penalty energy at t = 0
  double external_work_mJ() const;   // the largest of the drive's, cannula's, supports' and body load's work
};

class LspgInsertion {
 public:
  // The needle and the tissue are advanced by this object; both must outlive it.
  LspgInsertion(NeedleDynamics& needle, SpgTissue& tissue, const ContactSurface& surface, const ContactOptions& contact,
                const CouplingOptions& coupling);

  // One coupling step, shortened to land on end_time_ms.
  void step(double end_time_ms);

  double time_ms() const { return tissue_dynamics_.time_ms(); }
  long steps() const { return steps_; }
  double last_step_ms() const { return last_dt_ms_; }
  long needle_steps() const { return needle_.steps(); }
  const ContactReport& contact() const { return contact_.report(); }
  NeedleTissueContact& contact_model() { return contact_; }
  const NeedleTissueContact& contact_model() const { return contact_; }
  const InsertionEnergy& energy() const { return energy_; }
  double max_energy_error() const { return max_energy_error_; }
  int max_particles_inside() const { return max_inside_; }
  double max_depth_mm() const { return max_depth_; }
  long bonds_broken() const { return static_cast<long>(tissue_.bonds().broken_count); }
  long bonds_cut_by_needle() const { return static_cast<long>(tissue_.bonds().cut_count - bonds_cut_by_crack_); }
  std::int64_t particles_opened_by_slit() const { return slit_.opened(); }
  std::int64_t bonds_cut_by_crack() const { return bonds_cut_by_crack_; }
  double crack_s() const { return crack_s_; }  // wall time spent finding the bonds across the crack's fins
  double bond_cut_s() const { return bond_cut_s_; }  // wall time spent finding the bonds the needle cuts
  // Momenta (g mm/ms) and what the drive put in.
  Eigen::Vector3d tissue_momentum() const;
  Eigen::Vector3d needle_momentum() const { return needle_.momentum(); }
  const NeedleDynamics& needle() const { return needle_; }
  const SpgTissue& tissue() const { return tissue_; }
  const TissueDynamics& tissue_dynamics() const { return tissue_dynamics_; }

 private:
  void update_energy();

  NeedleDynamics& needle_;
  SpgTissue& tissue_;
  CouplingOptions options_;
  TissueDynamics tissue_dynamics_;
  NeedleTissueContact contact_;
  NeedleBondCut bond_cut_;
  SymmetrySlit slit_;
  TipCrack crack_;
  std::int64_t bonds_cut_by_crack_ = 0;
  double crack_s_ = 0;
  double bond_cut_s_ = 0;
  InsertionEnergy energy_;
  bool in_step_ = false;
  double step_start_ms_ = 0, step_dt_ms_ = 0, last_dt_ms_ = 0, max_energy_error_ = 0, max_depth_ = 0;
  int max_inside_ = 0;
  long steps_ = 0;
};

}  // namespace needle
