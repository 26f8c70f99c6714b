#include "runs/run_defaults.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "runs/json_file.h"
#include "runs/model_levels.h"

#ifndef NEEDLE_DATA_DIR
#define NEEDLE_DATA_DIR "data"
#endif

namespace needle {
using nlohmann::json;

std::string default_calibration_file(const std::string& model_level) {
  // A level's own calibration; a custom combination takes the default (fast) level's.
  const ModelLevel* level = find_model_level(model_level);
  return std::string(NEEDLE_DATA_DIR) + "/paper/" + (level ? level->calibration_file : find_model_level(kDefaultModelLevel)->calibration_file);
}

double calibrated_E(const std::string& path) {
  const json j = read_json_file(path, "calibration");
  NEEDLE_REQUIRE(j.contains("tissue_E_MPa") && j["tissue_E_MPa"].is_number() && j["tissue_E_MPa"].get<double>() > 0,
                 fmt::format("{}: tissue_E_MPa must be a positive number", path));
  return j["tissue_E_MPa"].get<double>();
}

Scene default_run_scene() {
  Scene s = parse_scene("{}", "(needle run defaults)");
  s.tissue.enabled = true;
  s.needle.mesh.size_mm = 0.4;
  s.solver.mass_scaling_dt_ms = 5e-6;
  s.tissue.path_refinement = 2;  // 0.2 mm particles within 1.2 mm of the path: the tip's bevels see tissue
  apply_model_level(s, kDefaultModelLevel, "the run defaults");
  return s;
}

}  // namespace needle
