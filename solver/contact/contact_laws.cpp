#include "solver/contact/contact_laws.h"

#include <fmt/format.h>

#include "core/input_error.h"
#include "solver/contact/penalty_contact.h"
#include "solver/contact/projection_contact.h"

namespace needle {
namespace {

std::unique_ptr<NeedleTissueContact> make_penalty(const ContactSurface& surface, const TissueParticles& particles,
                                                  const TissueMaterial& material, const ContactOptions& options) {
  return std::make_unique<PenaltyContact>(surface, particles, material, options);
}

std::unique_ptr<NeedleTissueContact> make_projection(const ContactSurface& surface, const TissueParticles& particles,
                                                     const TissueMaterial&, const ContactOptions& options) {
  return std::make_unique<ProjectionContact>(surface, particles, options);
}

}  // namespace

const std::vector<ContactLawEntry>& contact_laws() {
  static const std::vector<ContactLawEntry> laws = {
      {"penalty", "the frictional penalty contact", false, make_penalty},
      {"projection", "the kinematic (projection) contact", true, make_projection},
  };
  return laws;
}

const ContactLawEntry& contact_law(const std::string& name, const std::string& where) {
  std::string known;
  const std::vector<ContactLawEntry>& laws = contact_laws();
  for (size_t i = 0; i < laws.size(); ++i) {
    if (laws[i].name == name) return laws[i];
    known += (i == 0 ? "" : i + 1 == laws.size() ? " or " : ", ") + laws[i].name;
  }
  throw InputError(fmt::format("{}: must be {} (got '{}')", where, known, name));
}

std::unique_ptr<NeedleTissueContact> make_tissue_contact(const ContactSurface& surface, const TissueParticles& particles,
                                                         const TissueMaterial& material, const ContactOptions& options) {
  options.validate();
  return contact_law(options.law).make(surface, particles, material, options);
}

}  // namespace needle
