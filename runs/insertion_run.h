#pragma once
// The coupled L-SPG insertion of a scene (tissue.enabled): needle, particles, contact, solve, and the
// run folder (docs/scenes.md): scene.json, history.csv, facet_forces.csv, summary.json, needle.pvd and
// tissue.pvd with frames/, run.log. Used by `needle simulate` and `needle run`.
#include <string>

#include "runs/run_driver.h"
#include "runs/scene.h"

namespace needle {


// The run defaults of `needle run`, `paper`, `calibrate` and design sweeps: the paper's scene with tissue, the
// needle fidelity that keeps a 30 mm run within minutes and the fast model level (runs/model_levels.h;
// docs/insertion.md measures its error; `--model full` is the reference). The tissue's E is the card's
// (0.665 MPa); `needle run` replaces it by the calibrated one (default_calibration_file()).
Scene default_run_scene();
// The model level of the run defaults.
inline constexpr const char* kDefaultModelLevel = "fast";

// The SB calibration shipped with the toolkit for a model level: the E that makes the paper's SB deflect as
// measured with that model, which `needle run` uses unless told otherwise. data/paper/calibration_sb.json is the
// default level's (fast); data/paper/calibration_sb_full.json the full model's, which the projection level
// shares (it has none of its own). Any other level (custom) gets the default level's.
std::string default_calibration_file(const std::string& model_level = kDefaultModelLevel);
// E from a calibration file written by `needle calibrate` (its tissue_E_MPa); InputError naming the file otherwise.
double calibrated_E(const std::string& path);

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
