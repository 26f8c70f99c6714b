#pragma once
// The needle alone (a scene without tissue): built from the scene, driven through the cannula by its
// profile, run by the run driver (run_driver.h) into a run folder: scene.json, history.csv (tip, drive
// reaction, energies, cannula contact), summary.json, needle.pvd with frames/, run.log (docs/scenes.md).
#include "runs/run_driver.h"
#include "runs/scene.h"

namespace needle {

// InputError (nothing written) for bad input; SolverError after writing the folder if the solver stopped.
void run_needle_alone(const Scene& scene, const RunOptions& options);

}  // namespace needle
