#pragma once
// The insertion's model levels: named sets of the solver's speed-for-accuracy choices, so that a user (and
// `needle bench`) can ask for "the fast model" or "the full model" without knowing the scene keys:
//   full        the FE needle (explicit, subcycled) and the penalty contact: the reference, the paper's kind of model;
//   projection  the FE needle and the kinematic contact: the contact no longer sets the step (one lever);
//   fast        the implicit needle, the kinematic contact and the tissue mass-scaled to half the needle's step: no
//               subcycling, and the few particles squeezed under the tip no longer set everybody's step;
//               ellipsoidal kernel supports, so the graded lattice's coarse particles reach as many neighbours as
//               the fine ones (solver/tissue/kernel_supports.h); and the tissue away from the needle stepped at up to
//               8 times the coupling step (solver/tissue/tissue_rate_levels.h).
// Each level sets needle.model, tissue.contact.law, solver.tissue_mass_scaling, tissue.spg.support and
// solver.tissue_rate_levels; every other key stays the scene's. (The implicit needle needs the kinematic contact: a penalty's force changes within a needle step.)
#include <string>
#include <vector>

#include "runs/scene.h"

namespace needle {

struct ModelLevel {
  std::string name, needle_model, contact_law;
  bool tissue_mass_scaling = false;
  SupportShape support = SupportShape::sphere;
  int tissue_rate_levels = 0;  // multi-rate stepping of the tissue (solver.tissue_rate_levels; 0: one rate)
  std::string description;
  std::string calibration_file;  // its shipped SB calibration, in data/paper/ (`needle calibrate` with that level)
};

// The reference level, against which the others' error is measured (`needle bench insertion`).
inline constexpr const char* kReferenceModelLevel = "full";

const std::vector<ModelLevel>& model_levels();
// Sets the level's keys; InputError naming where and the known levels for an unknown name.
void apply_model_level(Scene& scene, const std::string& name, const std::string& where = "--model");
// The level a scene's keys make, or "custom" (e.g. a rigid needle).
std::string model_level_of(const Scene& scene);
// The level named so; nullptr for another name ("custom").
const ModelLevel* find_model_level(const std::string& name);
// InputError for a combination no level allows: the implicit needle with the penalty contact.
void check_model_combination(const Scene& scene);
// The needle model, the contact law and the tissue's speed choices (mass scaling, ellipsoidal supports, multi-rate) in
// a run's one-line description (the paper report), in their registries' words, with the level they make. The full
// level's needle and contact go unnamed, and so does a needle that does not take the coupling step with that contact
// (the rigid one, which the report says elsewhere); empty when nothing is said.
std::string describe_model_choices(const Scene& scene);

}  // namespace needle
