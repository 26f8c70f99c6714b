#pragma once
// The needle-tissue contact laws by name (ContactOptions::law): "penalty" (penalty_contact.h), the
// frictional penalty whose stiffness caps the coupling step, and "projection" (projection_contact.h), the
// kinematic contact that leaves the step to the tissue. A new law is one file that implements
// NeedleTissueContact and one line in contact_laws.cpp; what the rest of the code needs to know of a law is a
// trait on its entry, never its name.
#include <memory>
#include <string>
#include <vector>

#include "solver/contact/needle_tissue_contact.h"

namespace needle {

struct ContactLawEntry {
  std::string name;
  std::string phrase;  // the law in a model's description, e.g. "the kinematic (projection) contact"
  // The needle's load from the law is constant over the needle's step (the kinematic law hands it one impulse a
  // step); a penalty's force changes within the step, which a needle that holds its loads over its step (the
  // implicit one) cannot follow.
  bool constant_over_needle_step;
  std::unique_ptr<NeedleTissueContact> (*make)(const ContactSurface& surface, const TissueParticles& particles,
                                               const TissueMaterial& material, const ContactOptions& options);
};

// The registered laws, in the order messages list them.
const std::vector<ContactLawEntry>& contact_laws();
// The law registered as name; InputError "where: must be penalty or projection (got 'name')" otherwise.
const ContactLawEntry& contact_law(const std::string& name, const std::string& where = "tissue.contact.law");

// InputError for an unknown law or bad options.
std::unique_ptr<NeedleTissueContact> make_tissue_contact(const ContactSurface& surface, const TissueParticles& particles,
                                                         const TissueMaterial& material, const ContactOptions& options);

}  // namespace needle
