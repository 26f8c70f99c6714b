#pragma once
// The needle models by name: what a scene's needle.model selects (docs/architecture.md). Each is one
// file implementing NeedleModel and one line in needle_models.cpp.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/needle/needle_dynamics.h"
#include "solver/needle/needle_model.h"

namespace needle {

// What any needle model may be built from; the FE needle and the supports must outlive the model.
struct NeedleModelInputs {
  const FeNeedle& needle;
  NeedleSupports supports;               // the driven base, the symmetry plane and the insertion profile
  std::optional<CannulaOptions> cannula;  // absent: no cannula
  NeedleDynamicsOptions options;
};

// What the rest of the code needs to know of a model is a trait on its entry, never its name.
struct NeedleModelEntry {
  std::string name, description;
  std::string phrase;  // the model in a run's description, e.g. "the implicit linear needle"
  bool mass_scaled;    // it takes explicit steps, which selective mass scaling lengthens (a rigid needle takes any step)
  bool runs_alone;     // a needle-alone run (no tissue) can drive it: the explicit FE needle with its cannula
  // It steps at the coupling step (solver.implicit_needle_step_ms), holding the contact's loads over its step: the
  // contact law must keep them constant over it, and the tissue's mass scaling aims at a share of its step.
  bool takes_coupling_step;
  std::unique_ptr<NeedleModel> (*make)(const NeedleModelInputs& inputs);
  // The needle section's boolean key that is an older way to select it (`rigid: true`), or empty. A scene reads the key,
  // and its effective scene still writes it, so that stored scenes read the same.
  std::string legacy_key = {};
};

// The model a scene's needle runs when it names none (the first registered: the explicit FE needle).
const NeedleModelEntry& default_needle_model();

// The registered models, in the order --help lists them.
const std::vector<NeedleModelEntry>& needle_models();
// The model registered as name; InputError listing the known names otherwise.
std::unique_ptr<NeedleModel> make_needle_model(const std::string& name, const NeedleModelInputs& inputs);
// The model registered as name; InputError naming where and the known names otherwise (scene readers check
// before building anything).
const NeedleModelEntry& needle_model(const std::string& name, const std::string& where = "needle.model");

}  // namespace needle
