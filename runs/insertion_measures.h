#pragma once
// What a coupled run's current state measures beside the deflection: the groove fill (solver/insertion/groove_fill.h)
// and the tissue's minimum principal strain where the paper's model shows it (strain_probes.h), each read in the
// needle's reference frame as the contact pulls the particles back.
#include <nlohmann/json.hpp>

#include "runs/scene.h"
#include "runs/scene_needle.h"
#include "solver/insertion/coupled_insertion.h"
#include "solver/insertion/groove_fill.h"
#include "solver/insertion/strain_probes.h"

namespace needle {

// The groove fill of the run's current state; empty without a groove.
GrooveFill run_groove_fill(CoupledInsertion& run, const SceneNeedle& needle, const Scene& scene);
// The strain probes of the run's current state.
StrainProbes run_strain_probes(CoupledInsertion& run, const SceneNeedle& needle, const Scene& scene);
// The probes as summary.json writes them, with the insertion and deflection they were read at.
nlohmann::json strain_probes_json(const StrainProbes& probes, double insertion_mm, double deflection_mm);

}  // namespace needle
