#include "runs/recipe_json.h"

#include <fmt/format.h>
#include <fstream>
#include <set>

#include "runs/json_object_reader.h"
#include "core/input_error.h"
#include "runs/json_file.h"
#include "core/input_file.h"

namespace needle {
namespace {

using nlohmann::json;

}  // namespace

GrindingRecipe recipe_from_json(const json& root, const std::string& source) {
  GrindingRecipe recipe;
  ObjectReader top(root, "recipe", source);
  if (top.has("preset")) {
    recipe = preset_recipe(top.text("preset", ""));
  }
  recipe.name = top.text("name", recipe.name);
  if (top.has("rod")) {
    ObjectReader rod(top.child("rod"), "rod", source);
    recipe.rod.diameter_mm = rod.number("diameter_mm", recipe.rod.diameter_mm);
    recipe.rod.length_mm = rod.number("length_mm", recipe.rod.length_mm);
    rod.finish();
  }
  if (top.has("groove")) {
    const json& g = top.child("groove");
    if (g.is_null()) {
      recipe.groove.reset();
    } else {
      Groove groove = recipe.groove.value_or(Groove{});
      ObjectReader reader(g, "groove", source);
      groove.length_mm = reader.number("length_mm", groove.length_mm);
      groove.remaining_thickness_mm = reader.number("remaining_thickness_mm", groove.remaining_thickness_mm);
      groove.start_behind_tip_mm = reader.number("start_behind_tip_mm", groove.start_behind_tip_mm);
      reader.finish();
      recipe.groove = groove;
    }
  }
  if (top.has("tip")) {
    ObjectReader tip(top.child("tip"), "tip", source);
    NEEDLE_REQUIRE(!(tip.has("d_a_mm") && tip.has("y_mm")),
                   fmt::format("{}: give the tip point as either 'tip.d_a_mm' or 'tip.y_mm', not both", source));
    if (tip.has("d_a_mm")) {
      NEEDLE_REQUIRE(recipe.groove.has_value(), fmt::format("{}: 'tip.d_a_mm' needs a groove (d_a is measured from its face)", source));
      recipe.tip_y_mm = groove_floor_y_mm(recipe.rod, *recipe.groove) + tip.number("d_a_mm", 0.0);
    }
    if (tip.has("y_mm")) recipe.tip_y_mm = tip.number("y_mm", 0.0);
    tip.finish();
  }
  if (top.has("grinds")) {
    const json& list = top.child("grinds");
    NEEDLE_REQUIRE(list.is_array(), fmt::format("{}: 'grinds' must be a list", source));
    recipe.grinds.clear();
    for (size_t i = 0; i < list.size(); ++i) {
      ObjectReader reader(list[i], fmt::format("grinds[{}]", i), source);
      Grind grind;
      grind.name = reader.text("name", fmt::format("facet_{}", i));
      grind.tilt_deg = reader.number("tilt_deg", std::nan(""));
      grind.rotation_deg = reader.number("rotation_deg", 0.0);
      NEEDLE_REQUIRE(!(reader.has("depth_mm") && reader.has("through_tip")),
                     fmt::format("{}: grinds[{}] has both 'depth_mm' and 'through_tip'", source, i));
      grind.through_tip = reader.boolean("through_tip", !reader.has("depth_mm"));
      grind.depth_mm = reader.number("depth_mm", 0.0);
      NEEDLE_REQUIRE(std::isfinite(grind.tilt_deg), fmt::format("{}: grinds[{}] needs 'tilt_deg'", source, i));
      reader.finish();
      recipe.grinds.push_back(grind);
    }
  }
  if (top.has("tessellation")) {
    ObjectReader t(top.child("tessellation"), "tessellation", source);
    TessellationOptions& o = recipe.tessellation;
    o.chord_tolerance_mm = t.number("chord_tolerance_mm", o.chord_tolerance_mm);
    o.axial_spacing_mm = t.number("axial_spacing_mm", o.axial_spacing_mm);
    o.shaft_axial_spacing_mm = t.number("shaft_axial_spacing_mm", o.shaft_axial_spacing_mm);
    o.min_segments_per_arc = static_cast<int>(t.number("min_segments_per_arc", o.min_segments_per_arc));
    t.finish();
  }
  top.finish();
  return recipe;
}

GrindingRecipe read_recipe_file(const std::string& path) {
  check_input_file(path, "recipe");
  std::ifstream in(path);
  NEEDLE_REQUIRE(in.good(), fmt::format("cannot read recipe '{}': no such file", path));
  json root;
  try {
    root = parse_json_refusing_duplicates(in, path);
  } catch (const json::exception& e) {  // a parse error, or a number too large (out_of_range)
    throw InputError(fmt::format("{}: not valid JSON: {}", path, json_error_words(e)));
  }
  return recipe_from_json(root, path);
}

json recipe_to_json(const GrindingRecipe& r) {
  json grinds = json::array();
  for (const Grind& g : r.grinds) {
    json item = {{"name", g.name}, {"tilt_deg", g.tilt_deg}, {"rotation_deg", g.rotation_deg}};
    if (g.through_tip) item["through_tip"] = true;
    else item["depth_mm"] = g.depth_mm;
    grinds.push_back(item);
  }
  json out = {{"name", r.name},
              {"rod", {{"diameter_mm", r.rod.diameter_mm}, {"length_mm", r.rod.length_mm}}},
              {"grinds", grinds},
              {"tessellation",
               {{"chord_tolerance_mm", r.tessellation.chord_tolerance_mm},
                {"axial_spacing_mm", r.tessellation.axial_spacing_mm},
                {"shaft_axial_spacing_mm", r.tessellation.shaft_axial_spacing_mm},
                {"min_segments_per_arc", r.tessellation.min_segments_per_arc}}}};
  out["groove"] = r.groove ? json{{"length_mm", r.groove->length_mm},
                                  {"remaining_thickness_mm", r.groove->remaining_thickness_mm},
                                  {"start_behind_tip_mm", r.groove->start_behind_tip_mm}}
                           : json(nullptr);
  if (r.tip_y_mm) out["tip"] = {{"y_mm", *r.tip_y_mm}};
  return out;
}

}  // namespace needle
