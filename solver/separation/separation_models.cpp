#include "solver/separation/separation_models.h"

#include "solver/separation/needle_bond_cut.h"

namespace needle {

void SeparationOptions::validate(const std::string& where) const {
  slit.validate(where + ".slit");
  crack.validate(where + ".crack");
  lip.validate(where + ".lip_release");
}

std::vector<std::unique_ptr<SeparationModel>> make_separation_models(const SeparationOptions& options, const ContactSurface& surface) {
  options.validate();
  const Eigen::MatrixX3d& needle_reference_mm = surface.reference_positions();
  std::vector<std::unique_ptr<SeparationModel>> models;
  if (options.needle_cut) models.push_back(std::make_unique<NeedleBondCut>(surface));
  if (options.slit.enabled()) models.push_back(std::make_unique<SymmetrySlit>(needle_reference_mm, options.slit));
  if (options.crack.enabled()) models.push_back(std::make_unique<TipCrack>(needle_reference_mm, options.crack));
  if (options.lip.enabled()) models.push_back(std::make_unique<LipRelease>(needle_reference_mm, options.lip));
  return models;
}

}  // namespace needle
