#pragma once
// One path from a command to a scene (issue 49): what `needle run`, `paper`, `calibrate`, `simulate` and a sweep's or
// an optimisation's case ask for (a scene file or the run defaults, a needle, a model level, the tissue's E, the
// command's keys, the scene flags and --set) becomes the Scene they run, and where its E came from. The same request
// gives the same scene in every command; the default tissue is the one calibrated on SB for the scene's model level
// (a command that starts from the card, as `calibrate` does, says so).
//
// The order: the scene file (or the run defaults), the needle, the model level; then the tissue's E (given, from a
// calibration, from the scene file, or the shipped SB calibration of the model level the scene will have once the
// settings are applied); then the command's own keys; then the settings (the scene flags' rows and --set, or a study's
// keys), read together by the scene reader. A setting of E wins over all of it and says so.
#include <cmath>
#include <string>
#include <vector>

#include "runs/scene.h"

namespace needle {

struct SceneRequest {
  std::string scene_file;                  // empty: the run defaults (runs/insertion_run.h, default_run_scene)
  std::string preset, recipe_file;         // the needle over the scene's: at most one of preset, recipe and d_a_mm
  double d_a_mm = std::nan("");
  std::string model;                       // a model level over the scene's (runs/model_levels.h); empty: the scene's
  std::string model_where = "--model";     // how messages name it
  double tissue_E_MPa = std::nan("");      // the tissue's E, given
  std::string calibration_file;            // the tissue's E from this calibration (calibration.json)
  bool card_by_default = false;            // without E or a calibration, the run defaults keep the card's E (calibrate)
  bool tissue_on = true;                   // switch the tissue on (false: the scene's own choice; simulate runs a needle alone)
  std::vector<NamedSceneSetting> command_settings;  // the command's own keys (run's --frames, --rigid ...): after E
  std::vector<NamedSceneSetting> settings;  // the scene flags and --set, or a study's keys: last, read together
};

struct ResolvedScene {
  Scene scene;
  std::string E_source;          // "calibrated on SB: FILE", "given with --tissue-E-MPa", "from the scene FILE", ...
  std::string calibration_file;  // the calibration E came from; empty if none
};

// InputError for a request that contradicts itself or a setting the reader refuses.
ResolvedScene resolve_scene(const SceneRequest& request);

}  // namespace needle
