#include "solver/needle/needle_models.h"

#include <fmt/format.h>

#include "core/input_error.h"
#include "solver/needle/implicit_needle.h"
#include "solver/needle/rigid_needle.h"

namespace needle {
namespace {

std::unique_ptr<NeedleModel> make_fe(const NeedleModelInputs& in) {
  return std::make_unique<NeedleDynamics>(in.needle, in.supports, in.cannula, in.options);
}

std::unique_ptr<NeedleModel> make_implicit(const NeedleModelInputs& in) {
  return std::make_unique<ImplicitNeedle>(in.needle, in.supports, in.cannula, in.options);
}

std::unique_ptr<NeedleModel> make_rigid(const NeedleModelInputs& in) {
  return std::make_unique<RigidNeedle>(in.needle, in.supports.profile, in.supports.direction, in.options.max_energy_error);
}

std::string known_names() {
  std::string names;
  for (const NeedleModelEntry& m : needle_models()) names += (names.empty() ? "" : ", ") + m.name;
  return names;
}

}  // namespace

const std::vector<NeedleModelEntry>& needle_models() {
  static const std::vector<NeedleModelEntry> models = {
      {"fe", "explicit T4/T10 finite elements with the driven base and the rigid cannula, subcycled in the tissue's step",
       "the explicit FE needle", true, true, false, make_fe},
      {"implicit", "the same mesh, linear elastic, implicit Newmark steps on a factored matrix at the coupling step: no subcycling",
       "the implicit linear needle", false, false, true, make_implicit},
      {"rigid", "every node follows the drive: no deflection, no cannula, no step limit", "the rigid needle", false, false, false,
       make_rigid, "rigid"},
  };
  return models;
}

const NeedleModelEntry& default_needle_model() { return needle_models().front(); }

const NeedleModelEntry& needle_model(const std::string& name, const std::string& where) {
  for (const NeedleModelEntry& m : needle_models())
    if (m.name == name) return m;
  throw InputError(fmt::format("{}: unknown needle model '{}' (known: {})", where, name, known_names()));
}

std::unique_ptr<NeedleModel> make_needle_model(const std::string& name, const NeedleModelInputs& inputs) {
  return needle_model(name).make(inputs);
}

}  // namespace needle
