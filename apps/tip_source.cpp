#include "apps/tip_source.h"

#include "runs/recipe_json.h"
#include "core/input_error.h"

namespace needle {

void add_tip_source_options(CLI::App& command, TipSource& s) {
  command.add_option("--preset", s.preset, "Paper tip: SB, LMB, AMB or HMB");
  command.add_option("--d-a", s.d_a_mm, "Multi-bevel tip with tip point A this far above the groove face (mm)");
  command.add_option("--recipe", s.recipe_file, "Grinding recipe JSON file (see docs/geometry.md)");
  command.add_option("--top-tilt-deg", s.angles.top_tilt_deg, "Multi-bevel: top bevel tilt")->capture_default_str();
  command.add_option("--bevel-tilt-deg", s.angles.bevel_tilt_deg, "Multi-bevel: bottom and side bevel tilt")->capture_default_str();
  command.add_option("--side-rotation-deg", s.angles.side_rotation_deg, "Multi-bevel: side bevel rotation (+/-)")->capture_default_str();
  command.add_option("--rod-length-mm", s.rod_length_mm, "Rod length from A to the base (default 40)");
  command.add_option("--groove-start-mm", s.groove_start_mm, "Groove front wall distance behind A (default 3)");
  command.add_option("--chord-tolerance-mm", s.chord_tolerance_mm, "Largest gap between the polygonal and the true rod (default 0.001)");
}

GrindingRecipe recipe_from_source(const TipSource& o) {
  const int sources = !o.preset.empty() + !std::isnan(o.d_a_mm) + !o.recipe_file.empty();
  NEEDLE_REQUIRE(sources == 1, "say which tip: exactly one of --preset, --d-a or --recipe");
  GrindingRecipe recipe;
  if (!o.preset.empty()) recipe = preset_recipe(o.preset);
  if (!o.recipe_file.empty()) recipe = read_recipe_file(o.recipe_file);
  if (!std::isnan(o.rod_length_mm)) recipe.rod.length_mm = o.rod_length_mm;
  if (!std::isnan(o.groove_start_mm)) {
    NEEDLE_REQUIRE(recipe.groove.has_value() || !std::isnan(o.d_a_mm), "--groove-start-mm given but the recipe has no groove");
  }
  if (!std::isnan(o.d_a_mm)) {
    Groove groove;
    if (!std::isnan(o.groove_start_mm)) groove.start_behind_tip_mm = o.groove_start_mm;
    recipe = multi_bevel_recipe(o.d_a_mm, o.angles, recipe.rod, groove);
  } else if (!std::isnan(o.groove_start_mm)) {
    recipe.groove->start_behind_tip_mm = o.groove_start_mm;
  }
  if (!std::isnan(o.chord_tolerance_mm)) recipe.tessellation.chord_tolerance_mm = o.chord_tolerance_mm;
  return recipe;
}

}  // namespace needle
