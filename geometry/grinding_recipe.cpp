#include "geometry/grinding_recipe.h"

#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

double groove_floor_y_mm(const Rod& rod, const Groove& groove) {
  return -0.5 * rod.diameter_mm + groove.remaining_thickness_mm;
}

GrindingRecipe multi_bevel_recipe(double d_a_mm, const MultiBevelAngles& angles, const Rod& rod,
                                  const Groove& groove) {
  GrindingRecipe recipe;
  recipe.name = "multi-bevel";
  recipe.rod = rod;
  recipe.groove = groove;
  recipe.tip_y_mm = groove_floor_y_mm(rod, groove) + d_a_mm;
  recipe.grinds = {
      {"top", angles.top_tilt_deg, 0.0, true, 0.0},
      {"bottom", angles.bevel_tilt_deg, 180.0, true, 0.0},
      {"side_pos", angles.bevel_tilt_deg, angles.side_rotation_deg, true, 0.0},
      {"side_neg", angles.bevel_tilt_deg, -angles.side_rotation_deg, true, 0.0},
  };
  return recipe;
}

GrindingRecipe single_bevel_recipe(const LancetAngles& lancets, double top_tilt_deg, const Rod& rod,
                                   const Groove& groove) {
  GrindingRecipe recipe;
  recipe.name = "single bevel with lancets";
  recipe.rod = rod;
  recipe.groove = groove;
  recipe.tip_y_mm = -0.5 * rod.diameter_mm;  // A on the bottom of the rod
  recipe.grinds = {
      {"top", top_tilt_deg, 0.0, true, 0.0},
      {"lancet_pos", lancets.tilt_deg, lancets.rotation_deg, true, 0.0},
      {"lancet_neg", lancets.tilt_deg, -lancets.rotation_deg, true, 0.0},
  };
  return recipe;
}

std::vector<std::string> preset_names() { return {"SB", "LMB", "AMB", "HMB"}; }

GrindingRecipe preset_recipe(const std::string& name) {
  GrindingRecipe recipe;
  if (name == "SB") {
    recipe = single_bevel_recipe();
  } else if (name == "LMB") {
    recipe = multi_bevel_recipe(-0.22);
  } else if (name == "AMB") {
    recipe = multi_bevel_recipe(0.0);
  } else if (name == "HMB") {
    recipe = multi_bevel_recipe(0.37);
  } else {
    throw InputError(fmt::format("unknown preset '{}': choose one of SB, LMB, AMB, HMB", name));
  }
  recipe.name = name;
  return recipe;
}

namespace {
constexpr double kMaxRodSegments = 2.0e4;   // around the rod, as the rings along it
constexpr double kMaxRodTriangles = 2.0e7;  // the whole tessellation, before the booleans
}  // namespace

void validate_recipe(const GrindingRecipe& recipe) {
  const double diameter = recipe.rod.diameter_mm;
  const double radius = 0.5 * diameter;
  NEEDLE_REQUIRE(std::isfinite(diameter) && diameter > 0.0,
                 fmt::format("rod diameter must be positive, got {} mm", diameter));
  NEEDLE_REQUIRE(std::isfinite(recipe.rod.length_mm) && recipe.rod.length_mm > 0.0,
                 fmt::format("rod length must be positive, got {} mm", recipe.rod.length_mm));
  NEEDLE_REQUIRE(!recipe.grinds.empty(), "the recipe has no grinding operation: nothing makes a tip");
  NEEDLE_REQUIRE(std::isfinite(recipe.tessellation.chord_tolerance_mm) && recipe.tessellation.chord_tolerance_mm > 0.0 &&
                     recipe.tessellation.chord_tolerance_mm < 0.1 * radius,
                 fmt::format("chord tolerance must be in (0, {}) mm, got {} mm", 0.1 * radius,
                             recipe.tessellation.chord_tolerance_mm));
  NEEDLE_REQUIRE(std::isfinite(recipe.tessellation.axial_spacing_mm) && recipe.tessellation.axial_spacing_mm > 0.0,
                 fmt::format("axial spacing must be positive, got {} mm", recipe.tessellation.axial_spacing_mm));
  NEEDLE_REQUIRE(std::isfinite(recipe.tessellation.shaft_axial_spacing_mm) &&
                     recipe.tessellation.shaft_axial_spacing_mm > 0.0,
                 fmt::format("shaft axial spacing must be positive, got {} mm",
                             recipe.tessellation.shaft_axial_spacing_mm));
  NEEDLE_REQUIRE(recipe.rod.length_mm / recipe.tessellation.shaft_axial_spacing_mm <= 20000.0,
                 fmt::format("shaft axial spacing {} mm is too fine for a {} mm rod (over 20000 rings)",
                             recipe.tessellation.shaft_axial_spacing_mm, recipe.rod.length_mm));
  NEEDLE_REQUIRE(recipe.rod.length_mm / recipe.tessellation.axial_spacing_mm <= 20000.0,
                 fmt::format("axial spacing {} mm is too fine for a {} mm rod (over 20000 rings)",
                             recipe.tessellation.axial_spacing_mm, recipe.rod.length_mm));
  {
    // The work the tessellation makes, estimated before any: the segments around the rod that the chord tolerance
    // asks for, times the rings along it (an upper bound). A tolerance of 1e-12 mm asked for 1.8 million segments
    // and grew past 8 GB.
    const double segments = 2.0 * M_PI / (2.0 * std::acos(1.0 - recipe.tessellation.chord_tolerance_mm / radius));
    const double rings = recipe.rod.length_mm / recipe.tessellation.shaft_axial_spacing_mm +
                         recipe.rod.length_mm / recipe.tessellation.axial_spacing_mm;
    const double triangles = 2.0 * segments * rings;
    NEEDLE_REQUIRE(segments <= kMaxRodSegments && triangles <= kMaxRodTriangles,
                   fmt::format("chord tolerance {} mm makes about {:.3g} segments around the rod and {:.3g} triangles (limits {:.0e} "
                               "and {:.0e}): use a larger --chord-tolerance-mm (the default 0.001 makes {:.0f} segments)",
                               recipe.tessellation.chord_tolerance_mm, segments, triangles, kMaxRodSegments, kMaxRodTriangles,
                               std::ceil(M_PI / std::acos(1.0 - 1e-3 / radius))));
  }
  NEEDLE_REQUIRE(recipe.tessellation.min_segments_per_arc >= 1 && recipe.tessellation.min_segments_per_arc <= 256,
                 fmt::format("min segments per arc must be in [1, 256], got {}",
                             recipe.tessellation.min_segments_per_arc));
  bool any_through_tip = false;
  for (const Grind& grind : recipe.grinds) {
    NEEDLE_REQUIRE(!grind.name.empty(), "every grind needs a name (it tags the facet it makes)");
    NEEDLE_REQUIRE(std::isfinite(grind.tilt_deg) && grind.tilt_deg > 0.0 && grind.tilt_deg < 90.0,
                   fmt::format("grind '{}': tilt must be in (0, 90) degrees, got {}", grind.name,
                               grind.tilt_deg));
    NEEDLE_REQUIRE(std::isfinite(grind.rotation_deg),
                   fmt::format("grind '{}': rotation is not a number", grind.name));
    if (grind.through_tip) {
      any_through_tip = true;
    } else {
      NEEDLE_REQUIRE(std::isfinite(grind.depth_mm) && grind.depth_mm > 0.0 && grind.depth_mm <= diameter,
                     fmt::format("grind '{}': depth must be in (0, {}] mm (the rod diameter), got {} mm",
                                 grind.name, diameter, grind.depth_mm));
    }
    for (const Grind& other : recipe.grinds)
      NEEDLE_REQUIRE(&other == &grind || other.name != grind.name,
                     fmt::format("two grinds are named '{}': facet names must be unique", grind.name));
  }
  if (recipe.groove) {
    const Groove& g = *recipe.groove;
    NEEDLE_REQUIRE(std::isfinite(g.length_mm) && g.length_mm > 0.0,
                   fmt::format("groove length must be positive, got {} mm", g.length_mm));
    NEEDLE_REQUIRE(std::isfinite(g.remaining_thickness_mm) && g.remaining_thickness_mm > 0.0,
                   fmt::format("groove is deeper than the rod: remaining thickness must be positive, "
                               "got {} mm",
                               g.remaining_thickness_mm));
    NEEDLE_REQUIRE(g.remaining_thickness_mm < diameter,
                   fmt::format("groove remaining thickness {} mm must be less than the rod diameter "
                               "{} mm, or the groove removes nothing",
                               g.remaining_thickness_mm, diameter));
    NEEDLE_REQUIRE(std::isfinite(g.start_behind_tip_mm) && g.start_behind_tip_mm > 0.0,
                   fmt::format("groove start behind the tip must be positive, got {} mm",
                               g.start_behind_tip_mm));
    NEEDLE_REQUIRE(g.start_behind_tip_mm + g.length_mm < recipe.rod.length_mm,
                   fmt::format("groove ({} mm long, starting {} mm behind the tip) runs past the rod's "
                               "base at {} mm",
                               g.length_mm, g.start_behind_tip_mm, recipe.rod.length_mm));
  }
  if (any_through_tip) {
    NEEDLE_REQUIRE(recipe.tip_y_mm.has_value(),
                   "grinds through the tip point need the tip point: give d_a_mm or tip y_mm");
    const double tip_y = *recipe.tip_y_mm;
    NEEDLE_REQUIRE(std::isfinite(tip_y), "tip point y is not a number");
    const double floor_y = recipe.groove ? groove_floor_y_mm(recipe.rod, *recipe.groove) : 0.0;
    NEEDLE_REQUIRE(std::abs(tip_y) <= radius * (1.0 + 1e-12),
                   recipe.groove
                       ? fmt::format("d_a = {:.4g} mm puts tip point A at y = {:.4g} mm, outside the "
                                     "rod (|y| <= {} mm): d_a must lie in [{:.4g}, {:.4g}] mm",
                                     tip_y - floor_y, tip_y, radius, -radius - floor_y, radius - floor_y)
                       : fmt::format("tip point y = {:.4g} mm lies outside the rod (|y| <= {} mm)",
                                     tip_y, radius));
  }
}

}  // namespace needle
