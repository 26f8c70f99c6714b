#pragma once
// The run defaults: the scene `needle run`, `paper`, `calibrate` and design sweeps start from, and the shipped SB
// calibration of each model level that gives its tissue E (runs/scene_request.h resolves a command's scene with them).
#include <string>

#include "runs/scene.h"

namespace needle {

// The run defaults of `needle run`, `paper`, `calibrate` and design sweeps: the paper's scene with tissue, the
// needle fidelity that keeps a 30 mm run within minutes and the fast model level (runs/model_levels.h;
// docs/insertion.md measures its error; `--model full` is the reference). The tissue's E is the card's
// (0.665 MPa); the resolver replaces it by the calibrated one (default_calibration_file()).
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

}  // namespace needle
