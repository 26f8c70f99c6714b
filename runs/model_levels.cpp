#include "runs/model_levels.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <string>
#include <vector>

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
       "implicit linear needle at the coupling step, kinematic contact, tissue mass-scaled where its step is short (to half the needle's step): no subcycling; "
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

std::string describe_model_choices(const Scene& scene) {
  const ModelLevel& full = *find_model_level(kReferenceModelLevel);
  const std::string& needle_name = scene.needle.model;
  const std::string& law = scene.tissue.contact.law;
  const NeedleModelEntry& needle_entry = needle_model(needle_name);
  const bool mass_scaled = scene.solver.tissue_mass_scaling || scene.solver.tissue_mass_scaling_dt_ms > 0;
  const bool ellipsoids = scene.tissue.spg.support == SupportShape::ellipsoid;
  const int rate_levels = scene.solver.coupling.tissue_rate_levels;
  const std::string multirate =
      rate_levels > 0 ? fmt::format("the tissue away from the needle stepped at up to {} coupling steps (multi-rate)", 1 << rate_levels) : "";
  std::vector<std::string> choices;
  if (mass_scaled) choices.emplace_back("the tissue selectively mass-scaled");
  if (ellipsoids) choices.emplace_back("ellipsoidal kernel supports");
  if (!multirate.empty()) choices.push_back(multirate);
  const std::string listed = fmt::format("{}", fmt::join(choices, ", "));
  if (law == full.contact_law && !needle_entry.takes_coupling_step) return listed;
  std::string level_flag;  // the level these keys make, if any but the full one
  for (const ModelLevel& level : model_levels())
    if (level.name != full.name && level.needle_model == needle_name && level.contact_law == law && level.tissue_mass_scaling == mass_scaled &&
        (level.support == SupportShape::ellipsoid) == ellipsoids && level.tissue_rate_levels == rate_levels)
      level_flag = fmt::format(" (--model {})", level.name);
  return fmt::format("{} and {}{}{}", needle_entry.phrase, contact_law(law).phrase, listed.empty() ? "" : ", " + listed, level_flag);
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
