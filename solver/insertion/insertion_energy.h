#pragma once
// The coupled run's energy account. The bodies' balances hold on their own; the run's physical balance is
//   W_drive + W_cannula + W_firing = dKE + dU_needle + E_held + E_tissue (stored + plastic, -W_model) + E_penalty + D_friction,
// with E_penalty and D_friction from the contact law, not from the forces' work, so a contact that
// creates or destroys energy (lag, sticking) shows up as balance error.
#include "solver/contact/cutting_resistance.h"
#include "solver/contact/needle_tissue_contact.h"
#include "solver/needle/needle_model.h"
#include "solver/tissue/tissue_dynamics.h"

namespace needle {

struct InsertionEnergy {
  double tissue_kinetic_mJ = 0, tissue_internal_mJ = 0;  // internal: stored + plastically dissipated (-W_model)
  double needle_kinetic_mJ = 0, needle_strain_mJ = 0, needle_initial_mJ = 0, tissue_initial_kinetic_mJ = 0;
  double drive_work_mJ = 0, cannula_work_mJ = 0, tissue_reaction_work_mJ = 0, body_work_mJ = 0;
  double mass_scaling_mJ = 0;  // kinetic energy the tissue's mass scaling added to the particles (an input, tissue_mass_scaling.h)
  double firing_work_mJ = 0;  // the fired cannula's wall on the tissue (an input, cannula_firing.h)
  double needle_held_mJ = 0;  // the needle's kinetic energy its supports took when they held it still (held_needle.h)
  double contact_work_mJ = 0;  // work of the contact forces on both bodies (should equal -(E_penalty + D_friction))
  double relinearisation_energy_mJ = 0;  // the contact's penalty jumps at geometry updates (diagnostic, not in the balance)
  double penalty_energy_mJ = 0, initial_penalty_energy_mJ = 0, friction_dissipation_mJ = 0;  // initial: overlaps at t = 0; friction: with cutting

  // The account at t = 0 (the energy present then), and its terms now; the cutting resistance's work (when
  // there is one) is dissipation beside the contact's friction and damping.
  void start(const NeedleEnergy& needle, const EnergyBalance& tissue, const NeedleTissueContact& contact, const CuttingResistance* cutting);
  void update(const NeedleEnergy& needle, const EnergyBalance& tissue, const NeedleTissueContact& contact, const CuttingResistance* cutting,
              double firing_work_mJ = 0.0);
  // |inputs - stored - dissipated| / the largest term (the energy at t = 0 among them)
  double balance_error() const;
  double initial_energy_mJ() const;  // kinetic, strain and penalty energy at t = 0
  double external_work_mJ() const;   // the largest of the drive's, cannula's, supports', body load's and fired cannula's work
};

}  // namespace needle
