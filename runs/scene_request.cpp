#include "runs/scene_request.h"

#include <fmt/format.h>

#include "core/input_error.h"
#include "runs/run_defaults.h"
#include "runs/model_levels.h"

namespace needle {

ResolvedScene resolve_scene(const SceneRequest& r) {
  const int sources = !r.preset.empty() + !std::isnan(r.d_a_mm) + !r.recipe_file.empty();
  NEEDLE_REQUIRE(sources <= 1, "give one of --preset, --d-a or --recipe");
  NEEDLE_REQUIRE(std::isnan(r.tissue_E_MPa) || r.calibration_file.empty(), "give --tissue-E-MPa or --calibration, not both");
  ResolvedScene out;
  Scene& scene = out.scene;
  scene = r.scene_file.empty() ? default_run_scene() : read_scene(r.scene_file);
  if (r.tissue_on) scene.tissue.enabled = true;
  if (sources == 1) scene.needle.select_source(r.preset, r.d_a_mm, r.recipe_file);
  if (!r.model.empty()) apply_model_level(scene, r.model, r.model_where);

  if (!std::isnan(r.tissue_E_MPa)) {
    NEEDLE_REQUIRE(std::isfinite(r.tissue_E_MPa) && r.tissue_E_MPa > 0, fmt::format("--tissue-E-MPa must be a positive number (got {})", r.tissue_E_MPa));
    scene.tissue.material.E_MPa = r.tissue_E_MPa;
    out.E_source = "given with --tissue-E-MPa";
  } else if (!r.calibration_file.empty()) {
    scene.tissue.material.E_MPa = calibrated_E(r.calibration_file);
    out.calibration_file = r.calibration_file;
    out.E_source = fmt::format("calibrated on SB: {}", r.calibration_file);
  } else if (!r.scene_file.empty()) {
    out.E_source = fmt::format("from the scene {}", r.scene_file);
  } else if (r.card_by_default) {
    out.E_source = fmt::format("the card's, {:g} MPa (docs/solver.md)", scene.tissue.material.E_MPa);
  } else {
    // The shipped calibration of the model level the scene has once the settings are read (a --set or a flag may
    // change the level).
    const Scene probe = apply_named_scene_settings(scene, r.settings);
    out.calibration_file = default_calibration_file(model_level_of(probe));
    scene.tissue.material.E_MPa = calibrated_E(out.calibration_file);
    out.E_source = fmt::format("calibrated on SB: {} (the shipped calibration of the model level)", out.calibration_file);
  }
  scene.tissue.material.validate();
  scene = apply_named_scene_settings(scene, r.command_settings);
  const double E_before = scene.tissue.material.E_MPa;
  scene = apply_named_scene_settings(scene, r.settings);
  if (scene.tissue.material.E_MPa != E_before) {
    std::string by;
    for (const NamedSceneSetting& s : r.settings)
      if (s.setting.rfind("tissue.material.E", 0) == 0) by = s.shown;
    out.E_source = fmt::format("given with {}", by.empty() ? "--set" : by);
    out.calibration_file.clear();
  }
  return out;
}

}  // namespace needle
