#pragma once
// The needle-tissue contact laws by name (ContactOptions::law): "penalty" (penalty_contact.h), the
// frictional penalty whose stiffness caps the coupling step, and "projection" (projection_contact.h), the
// kinematic contact that leaves the step to the tissue. A new law is one file that implements
// NeedleTissueContact and one line in contact_laws.cpp.
#include <memory>

#include "solver/contact/needle_tissue_contact.h"

namespace needle {

// InputError for an unknown law or bad options.
std::unique_ptr<NeedleTissueContact> make_tissue_contact(const ContactSurface& surface, const TissueParticles& particles,
                                                         const TissueMaterial& material, const ContactOptions& options);

}  // namespace needle
