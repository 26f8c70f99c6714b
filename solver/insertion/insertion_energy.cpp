#include "solver/insertion/insertion_energy.h"

#include <algorithm>
#include <cmath>

namespace needle {

void InsertionEnergy::start(const NeedleEnergy& needle, const EnergyBalance& tissue, const NeedleTissueContact& contact,
                            const CuttingResistance* cutting) {
  needle_initial_mJ = needle.initial_mJ;
  initial_penalty_energy_mJ = contact.report().penalty_energy_mJ;
  tissue_initial_kinetic_mJ = tissue.initial_kinetic_mJ;
  update(needle, tissue, contact, cutting);
}

void InsertionEnergy::update(const NeedleEnergy& n, const EnergyBalance& t, const NeedleTissueContact& contact, const CuttingResistance* cutting,
                             double firing_work) {
  firing_work_mJ = firing_work;
  tissue_kinetic_mJ = t.kinetic_mJ;
  tissue_internal_mJ = -t.model_work_mJ;
  tissue_reaction_work_mJ = t.constraint_work_mJ;
  body_work_mJ = t.body_work_mJ;
  mass_scaling_mJ = t.mass_scaling_mJ;
  needle_kinetic_mJ = n.kinetic_mJ;
  needle_strain_mJ = n.strain_mJ;
  needle_held_mJ = n.held_mJ;
  drive_work_mJ = n.drive_work_mJ;
  cannula_work_mJ = n.cannula_work_mJ;
  contact_work_mJ = n.external_work_mJ + t.external_work_mJ;
  penalty_energy_mJ = contact.report().penalty_energy_mJ;
  friction_dissipation_mJ = contact.friction_dissipation_mJ();
  if (cutting) friction_dissipation_mJ += cutting->work_mJ();
  relinearisation_energy_mJ = contact.relinearisation_energy_mJ();
}

double InsertionEnergy::balance_error() const {
  const double inputs = drive_work_mJ + cannula_work_mJ + tissue_reaction_work_mJ + body_work_mJ + mass_scaling_mJ + firing_work_mJ;
  const double stored = (tissue_kinetic_mJ - tissue_initial_kinetic_mJ) + (needle_kinetic_mJ + needle_strain_mJ + needle_held_mJ - needle_initial_mJ) +
                        tissue_internal_mJ + (penalty_energy_mJ - initial_penalty_energy_mJ) + friction_dissipation_mJ;
  // The largest energy the run has held or exchanged, the energy present at t = 0 included.
  const double scale = std::max({std::abs(drive_work_mJ), std::abs(cannula_work_mJ), std::abs(firing_work_mJ), std::abs(tissue_reaction_work_mJ), std::abs(body_work_mJ),
                                 std::abs(mass_scaling_mJ), std::abs(tissue_kinetic_mJ), std::abs(needle_kinetic_mJ), std::abs(needle_strain_mJ), std::abs(needle_held_mJ),
                                 std::abs(tissue_internal_mJ), std::abs(penalty_energy_mJ), std::abs(friction_dissipation_mJ),
                                 std::abs(initial_energy_mJ()), 1e-300});
  return std::abs(inputs - stored) / scale;
}

double InsertionEnergy::initial_energy_mJ() const { return tissue_initial_kinetic_mJ + needle_initial_mJ + initial_penalty_energy_mJ; }

double InsertionEnergy::external_work_mJ() const {
  return std::max({std::abs(drive_work_mJ), std::abs(cannula_work_mJ), std::abs(tissue_reaction_work_mJ), std::abs(body_work_mJ),
                   std::abs(firing_work_mJ)});
}

}  // namespace needle
