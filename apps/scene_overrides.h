#pragma once
// The scene flags `needle run`, `paper` and `calibrate` share: each sets one scene key over the run defaults,
// checked with an InputError naming the flag, and can be written back as flags for a command line that
// regenerates a result.
#include <CLI/CLI.hpp>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "runs/scene.h"

namespace needle {

// The scene flags `needle run`, `paper` and `calibrate` share; NaN keeps the scene's value.
struct SceneOverrides {
  std::string model;  // the model level (runs/model_levels.h); empty: the scene's
  double travel_mm = std::nan(""), spacing_mm = std::nan(""), mesh_size_mm = std::nan("");
  std::optional<int> path_refinement;  // none: the scene's
  bool no_needle_cut = false;  // tissue separates by bond failure alone (the paper's model)
  double tissue_nu = std::nan(""), tissue_friction = std::nan("");  // the card's Poisson ratio; needle-tissue friction
  std::string tissue_law;  // empty: the scene's (TissueLaw names)
  double speed_m_per_s = std::nan("");  // insertion speed after the ramp (the paper's model 8; its experiment about 4)
  double decel_time_ms = std::nan("");  // the ramp to rest at the travel's end (0: none, the paper's model)
  double hold_ms = std::nan("");        // the base held still after the travel (0: none, the paper's model)
  std::vector<double> tissue_size_mm;   // the block's x, y, z (empty: the scene's; the paper's 40 x 8 x 2 mm half block)
  double slit_half_height_mm = std::nan("");  // the tissue opens in the symmetry plane behind the tip (0: no slit, the default)
  double relaxing_shear_fraction = std::nan("");  // viscoelastic relaxation of the shear stress (0: none, the card)
  double relaxation_time_ms = std::nan("");       // its time constant
  double cutting_pressure_MPa = std::nan("");     // the tissue's cutting resistance on the tip facets (0: none, the default)
  double crack_reach_mm = std::nan("");           // the tip's crack runs this far from tip point A (0: none, the default)
  std::vector<double> crack_angles_deg;           // its fins' directions in the cross-section (empty: the scene's; 0: horizontal)
  double crack_lead_mm = std::nan("");            // its front runs this far ahead of A (0: it opens as the tip passes)
  double groove_start_mm = std::nan("");          // the groove's front wall behind A (not given by the paper; the presets' 3 mm)
  double contact_skin_mm = std::nan("");          // the penalty contact's skin: particles are held this far off the surface (default: ContactOptions)
  double contact_stiffness_factor = std::nan(""); // the penalty's stiffness over the particle's own (default: ContactOptions)
  double tissue_entry_x_mm = std::nan("");        // the block's entry face ahead of A's start (0: at the cannula's front, the default)
  std::vector<std::string> settings;              // --set key=value: any scene key (apply_scene_settings), applied after the flags
};
// InputError naming the flag for a value that is not a positive number.
void apply_scene_overrides(Scene& scene, const SceneOverrides& overrides);
// The shipped SB calibration of the model level the scene will have once the overrides are applied (--model and
// --set come last): the default E of `needle run` and `needle paper`.
std::string default_calibration_after(const Scene& scene, const SceneOverrides& overrides);
// The flags run, paper and calibrate share: --model, --travel-mm, --spacing-mm, --path-refinement, --no-needle-cut, --tissue-nu,
// --tissue-friction, --tissue-law, --speed-m-per-s, --decel-time-ms, --hold-ms, --tissue-size-mm, --slit-half-height-mm, --relaxing-shear-fraction, --relaxation-time-ms, --cutting-pressure-mpa,
// --crack-reach-mm, --crack-angles-deg, --crack-lead-mm, --groove-start-mm, --contact-skin-mm, --contact-stiffness-factor,
// --tissue-entry-x-mm, and --set key=value for any scene key (each command
// adds --mesh-size-mm itself where it has it).
void add_scene_override_options(CLI::App* command, SceneOverrides& overrides);
// The flags that give these overrides again (each given value, with a leading space), for a command
// line that regenerates a result.
std::string scene_override_arguments(const SceneOverrides& overrides);

}  // namespace needle
