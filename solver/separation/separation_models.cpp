#include "solver/separation/separation_models.h"

#include "solver/separation/needle_bond_cut.h"

namespace needle {

void SeparationOptions::validate(const std::string& where) const {
  slit.validate(where + ".slit");
  crack.validate(where + ".crack");
  lip.validate(where + ".lip_release");
}

SeparationOptions scene_separation_defaults() {
  SeparationOptions options;
  options.lip.mode = LipReleaseMode::crushed;
  options.lip.depth_mm = kSceneCrushedLipDepthMm;
  return options;
}

std::vector<std::unique_ptr<SeparationModel>> make_separation_models(const SeparationOptions& options, const ContactSurface& surface) {
  options.validate();
  const Eigen::MatrixX3d& needle_reference_mm = surface.reference_positions();
  std::vector<std::unique_ptr<SeparationModel>> models;
  if (options.needle_cut) models.push_back(std::make_unique<NeedleBondCut>(surface));
  if (options.slit.enabled()) models.push_back(std::make_unique<SymmetrySlit>(needle_reference_mm, options.slit));
  if (options.crack.enabled()) models.push_back(std::make_unique<TipCrack>(needle_reference_mm, options.crack));
  // A tip point on the rod's bottom (SB) has no lip: no model, and its run files are as they were without one.
  if (options.lip.enabled() && LipRelease::lip_thickness_mm(needle_reference_mm) > kNoLipMm)
    models.push_back(std::make_unique<LipRelease>(needle_reference_mm, options.lip));
  return models;
}

}  // namespace needle
