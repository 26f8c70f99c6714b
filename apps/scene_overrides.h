#pragma once
// The scene flags `needle run`, `paper` and `calibrate` share, as a table: each flag is one row {flag, scene key,
// help} and stands for the setting `--set key=value` (runs/scene.h, apply_scene_settings). The scene reader checks
// every value, so a flag and its scene key accept and refuse the same things; its messages name the flag as given.
// The flags can be written back as a command line that regenerates a result.
#include <CLI/CLI.hpp>
#include <map>
#include <string>
#include <vector>

#include "runs/scene.h"

namespace needle {

// One convenience flag: the scene key it sets and how it takes its value.
struct SceneFlagRow {
  enum class Takes { value, list, nothing };  // one value; values separated by commas (a JSON list); none (a switch)
  std::string flag;                           // "--travel-mm"
  std::string key;                            // the scene key, with its unit: "motion.travel_mm"
  Takes takes = Takes::value;
  std::string switch_value;                   // Takes::nothing: the value the key takes ("false")
  std::string help;                           // names the default and the scene key
  int list_length = -1;                       // Takes::list: the number of values (-1: any)
};
// Every row, in the order a command line writes them back.
const std::vector<SceneFlagRow>& scene_flag_rows();

// The scene flags as given: --model, the rows' flags and --set.
struct SceneOverrides {
  std::string model;                                   // the model level (runs/model_levels.h); empty: the scene's
  std::map<std::string, std::vector<std::string>> given;  // a row's flag -> its values as typed (a switch: none)
  std::vector<std::string> settings;                   // --set key=value: any scene key, applied after the flags
  // As if the flag were given with these values (for commands and tests that build overrides in code).
  void give(const std::string& flag, std::vector<std::string> values = {});
};
// The flags' settings then --set's, as the scene reader reads them together (runs/scene_request.h: the request's
// settings; --model is the request's model level). An InputError names the flag as given (or --set's setting) and what
// the reader found wrong.
std::vector<NamedSceneSetting> scene_override_settings(const SceneOverrides& overrides);
// --model, --set and every row but --mesh-size-mm, which a command adds itself where it has it (add_scene_flag).
void add_scene_override_options(CLI::App* command, SceneOverrides& overrides);
// One row's flag, with the command's own help text (empty: the row's).
void add_scene_flag(CLI::App* command, SceneOverrides& overrides, const std::string& flag, const std::string& help = "");
// The flags that give these overrides again (each given value, with a leading space), for a command
// line that regenerates a result.
std::string scene_override_arguments(const SceneOverrides& overrides);

}  // namespace needle
