#pragma once
// The coupled L-SPG insertion of a scene (tissue.enabled): needle, particles, contact, solve, and the
// run folder (docs/scenes.md): scene.json, history.csv, facet_forces.csv, summary.json, needle.pvd and
// tissue.pvd with frames/, run.log. Used by `needle simulate` and `needle run`.
#include <string>

#include "runs/run_driver.h"
#include "runs/scene.h"

namespace needle {

// InputError (nothing written) for bad input; SolverError after writing the folder if the solver stopped
// (unless !throw_on_stop).
void run_insertion(const Scene& scene, const RunOptions& options);

// Runs the scene into options.out_dir unless that folder already holds a run (summary.json) of exactly
// this scene (scene.json, threads aside); true if it reused one. An interrupted `paper` or `calibrate` resumes this way.
bool run_insertion_unless_done(const Scene& scene, const RunOptions& options);

// Whether folder holds a run (summary.json, finished or stopped by the solver; not interrupted) of exactly this scene (scene.json), whatever
// worker threads it ran on (solver.threads, which does not change a run's results).
bool folder_holds_run_of(const Scene& scene, const std::string& folder);

}  // namespace needle
