#include "solver/contact/contact_laws.h"

#include "solver/contact/penalty_contact.h"
#include "solver/contact/projection_contact.h"

namespace needle {

std::unique_ptr<NeedleTissueContact> make_tissue_contact(const ContactSurface& surface, const TissueParticles& particles,
                                                         const TissueMaterial& material, const ContactOptions& options) {
  options.validate();
  if (options.law == "projection") return std::make_unique<ProjectionContact>(surface, particles, options);
  return std::make_unique<PenaltyContact>(surface, particles, material, options);
}

}  // namespace needle
