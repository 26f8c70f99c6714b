#include "studies/run_model_description.h"

#include <cmath>
#include <fmt/format.h>

#include "geometry/grinding_recipe.h"
#include "runs/model_levels.h"

namespace needle {

std::string describe_run_model(const Scene& scene, long particles) {
  const TissueScene& t = scene.tissue;
  std::string d = t.path_refinement > 1 ? fmt::format("{:g} mm particles, {:g} mm within {:g} mm of the path", t.spacing_mm,
                                                      t.spacing_mm / t.path_refinement, t.path_half_width_mm)
                                        : fmt::format("{:g} mm particles", t.spacing_mm);
  d += fmt::format(" ({} particles); the needle {} the bonds its body passes through", particles,
                   t.separation.needle_cut ? "cuts" : "does not cut");
  const auto say = [&d](const std::string& part) {
    if (!part.empty()) d += "; " + part;
  };
  say(t.material.describe());
  // The paper's 40 x 8 x 2 mm half block goes unnamed; another block is said.
  const TissueScene paper_block;
  if (t.size_mm != paper_block.size_mm)
    say(fmt::format("a {:g} x {:g} x {:g} mm half block (the paper's: {:g} x {:g} x {:g})", t.size_mm.x(), t.size_mm.y(), t.size_mm.z(),
                    paper_block.size_mm.x(), paper_block.size_mm.y(), paper_block.size_mm.z()));
  say(t.separation.slit.describe());
  say(t.separation.crack.describe());
  say(t.separation.lip.describe(scene_separation_defaults().lip));
  say(t.contact.describe());
  say(describe_model_choices(scene));
  say(t.cutting.describe());
  // The block's entry face at the tip's start is the default and goes unnamed; a shifted one is said.
  if (t.entry_x_mm != 0)
    say(fmt::format("the block's entry face is {:g} mm ahead of the tip's start (the particle lattice shifted against the path; the tip "
                    "ends that much less deep)",
                    t.entry_x_mm));
  say(scene.motion.describe());
  say(scene.cannula_firing.describe());
  // The presets' groove (its front wall 3 mm behind A) goes unnamed; another start is said.
  if (!std::isnan(scene.needle.groove_start_mm))
    say(fmt::format("the groove starts {:g} mm behind the tip point (the presets': {:g})", scene.needle.groove_start_mm,
                    Groove{}.start_behind_tip_mm));
  return d;
}

}  // namespace needle
