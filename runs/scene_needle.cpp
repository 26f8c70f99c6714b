#include "runs/scene_needle.h"

#include <cmath>

#include "runs/needle_build.h"
#include "runs/recipe_json.h"
#include "core/input_error.h"
#include "geometry/grinding_recipe.h"
#include "mesher/msh_file.h"
#include "mesher/vtk_files.h"

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
    if (!std::isnan(n.groove_start_mm)) {
      NEEDLE_REQUIRE(recipe.groove.has_value(), "a groove start was given (--groove-start-mm, scene key needle.groove_start_mm) but "
                                                "the recipe has no groove");
      recipe.groove->start_behind_tip_mm = n.groove_start_mm;
    }
    tip = resolve_tip(recipe);
  }
  const NeedleBuild build = build_needle(tip, n.half_model, n.mesh);
  out.name = tip.name;
  out.mesh = build.mesh;
  out.tip_point = tip.tip_point;
  out.groove = tip.groove;
  out.radius_mm = tip.radius_mm;
  if (!n.plain_rod) out.tip_facets = build.tip_facets;  // a plain rod's end is cut square, not ground
  out.mesh_seconds = build.mesh_seconds;
  return out;
}

NeedleDynamicsOptions scene_dynamics_options(const Scene& scene) {
  NeedleDynamicsOptions o;
  o.courant = scene.solver.courant;
  o.max_energy_error = scene.solver.max_energy_error;
  o.max_penetration_mm = scene.solver.max_penetration_mm;
  o.implicit_step_ms = scene.solver.implicit_needle_step_ms;
  return o;
}

void write_needle_vtu(const std::string& path, const NeedleModel& run) {
  TetMesh deformed = run.mesh();
  deformed.X = run.positions_mm();
  const ElementStresses stresses = run.element_stresses();
  write_vtu(path, deformed, {{"von_mises_MPa", stresses.von_mises_MPa}, {"cauchy_stress_MPa", stresses.cauchy_MPa}},
            {{"displacement_mm", run.displacements_mm()}, {"velocity_m_per_s", run.velocities_mm_per_ms()}}, VtkEncoding::binary);
}

}  // namespace needle
