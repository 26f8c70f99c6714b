#include "runs/model_levels.h"

#include <fmt/format.h>

#include "core/input_error.h"
#include "solver/contact/contact_laws.h"
#include "solver/needle/needle_models.h"

namespace needle {

const std::vector<ModelLevel>& model_levels() {
  static const std::vector<ModelLevel> levels = {
      {"full", "fe", "penalty", false, SupportShape::sphere, 0,
       "explicit FE needle subcycled in the tissue's step, frictional penalty contact (the reference)", "calibration_sb_full.json"},
      {"projection", "fe", "projection", false, SupportShape::sphere, 0, "explicit FE needle, kinematic contact: the tissue's own step",
       "calibration_sb_full.json"},
      {"fast", "implicit", "projection", true, SupportShape::ellipsoid, 3,
       "implicit linear needle at the coupling step, kinematic contact, tissue mass-scaled where its step is short (to a quarter of the needle's step): no subcycling; "
       "ellipsoidal kernel supports on the graded lattice; the tissue away from the needle at up to 8 coupling steps (multi-rate)",
       "calibration_sb.json"},
  };
  return levels;
}

void apply_model_level(Scene& scene, const std::string& name, const std::string& where) {
  std::string known;
  for (const ModelLevel& level : model_levels()) {
    if (level.name == name) {
      scene.needle.model = level.needle_model;
      scene.tissue.contact.law = level.contact_law;
      scene.solver.tissue_mass_scaling = level.tissue_mass_scaling;
      scene.tissue.spg.support = level.support;
      scene.solver.coupling.tissue_rate_levels = level.tissue_rate_levels;
      if (!level.tissue_mass_scaling) scene.solver.tissue_mass_scaling_dt_ms = 0;
      return;
    }
    known += (known.empty() ? "" : ", ") + level.name;
  }
  throw InputError(fmt::format("{}: unknown model level '{}' (known: {})", where, name, known));
}

const ModelLevel* find_model_level(const std::string& name) {
  for (const ModelLevel& level : model_levels())
    if (level.name == name) return &level;
  return nullptr;
}

std::string model_level_of(const Scene& scene) {
  for (const ModelLevel& level : model_levels())
    if (scene.needle.model == level.needle_model && scene.tissue.contact.law == level.contact_law &&
        (scene.solver.tissue_mass_scaling || scene.solver.tissue_mass_scaling_dt_ms > 0) == level.tissue_mass_scaling &&
        scene.tissue.spg.support == level.support)
      return level.name;
  return "custom";
}

void check_model_combination(const Scene& scene) {
  const NeedleModelEntry& model = needle_model(scene.needle.model);
  if (!model.takes_coupling_step || contact_law(scene.tissue.contact.law).constant_over_needle_step) return;
  std::string laws;
  for (const ContactLawEntry& law : contact_laws())
    if (law.constant_over_needle_step) laws += (laws.empty() ? "" : " or ") + law.name;
  throw InputError(fmt::format("needle.model {} needs tissue.contact.law {}: the {} needle holds its loads over its step, which a "
                               "{}'s force does not allow (--model fast sets both)",
                               model.name, laws, model.name, scene.tissue.contact.law));
}

}  // namespace needle
