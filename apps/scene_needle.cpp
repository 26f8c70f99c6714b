#include "apps/scene_needle.h"

#include "apps/needle_build.h"
#include "apps/recipe_json.h"
#include "geometry/grinding_recipe.h"
#include "mesher/msh_file.h"

namespace needle {

SceneNeedle build_scene_needle(const NeedleScene& n) {
  SceneNeedle out;
  if (!n.mesh_file.empty()) {
    out.name = n.mesh_file;
    out.mesh = read_msh(n.mesh_file);
    Eigen::Index distal = 0;
    out.mesh.X.col(0).maxCoeff(&distal);  // A: the most distal node
    out.tip_point = out.mesh.X.row(distal).transpose();
    return out;
  }
  TipGeometry tip;
  if (n.plain_rod) {
    tip = plain_rod_tip(1.0, n.length_mm);
  } else {
    GrindingRecipe recipe = !n.preset.empty() ? preset_recipe(n.preset)
                            : !n.recipe_file.empty() ? read_recipe_file(n.recipe_file)
                                                     : multi_bevel_recipe(n.d_a_mm);
    recipe.rod.length_mm = n.length_mm;
    tip = resolve_tip(recipe);
  }
  const NeedleBuild build = build_needle(tip, n.half_model, n.mesh);
  out.name = tip.name;
  out.mesh = build.mesh;
  out.tip_point = tip.tip_point;
  out.mesh_seconds = build.mesh_seconds;
  return out;
}

}  // namespace needle
