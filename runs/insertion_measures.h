#pragma once
// What a coupled run's current state measures beside the deflection: the groove fill (solver/insertion/groove_fill.h),
// the sample a fired cannula encloses (tissue_sample.h) and the tissue's minimum principal strain where the paper's model shows it (strain_probes.h), each read in the
// needle's reference frame as the contact pulls the particles back.
#include <nlohmann/json.hpp>

#include "runs/scene.h"
#include "runs/scene_needle.h"
#include "solver/insertion/coupled_insertion.h"
#include "solver/insertion/groove_fill.h"
#include "solver/insertion/strain_probes.h"
#include "solver/insertion/tissue_sample.h"

namespace needle {

// The groove fill of the run's current state; empty without a groove.
GrooveFill run_groove_fill(CoupledInsertion& run, const SceneNeedle& needle, const Scene& scene);
// Per particle: in contact with the needle's groove floor now.
std::vector<std::uint8_t> groove_floor_contacts(CoupledInsertion& run);
// The tissue sample the run's fired cannula encloses now (tissue_sample.h): in its bore, between the groove's walls within
// its stroke, above the groove's floor; touched_floor: per particle, whether it touched the floor (the run's choice of
// when: the run model ORs the contacts over the stroke).
TissueSample run_tissue_sample(CoupledInsertion& run, const SceneNeedle& needle, const CannulaFiring& firing,
                               std::vector<std::uint8_t> touched_floor);
// The strain probes of the run's current state.
StrainProbes run_strain_probes(CoupledInsertion& run, const SceneNeedle& needle, const Scene& scene);
// The probes as summary.json writes them, with the insertion and deflection they were read at.
nlohmann::json strain_probes_json(const StrainProbes& probes, double insertion_mm, double deflection_mm);

}  // namespace needle
