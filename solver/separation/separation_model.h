#pragma once
// A model that separates the tissue after each coupling step, from both bodies' new positions: the
// needle's cut (needle_bond_cut.h), the slit in the symmetry plane (symmetry_slit.h), the tip's crack
// (tip_crack.h). The coupled insertion applies each in the list separation_models.h builds from the
// scene; each reports its own summary entries and history columns. A new one is one file implementing
// this and one line in separation_models.cpp.
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "solver/needle/needle_model.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {

class SeparationModel {
 public:
  virtual ~SeparationModel() = default;
  virtual std::string name() const = 0;
  // Separates the tissue where this model says, with the needle at its current state.
  virtual void apply(SpgTissue& tissue, const NeedleModel& needle) = 0;
  // Its own entries in a run's summary.json, from the tissue at the run's end.
  virtual void add_summary(nlohmann::json& summary, const SpgTissue& tissue) const = 0;
  // Its own columns in a run's history.csv (names, and the values now, formatted).
  virtual std::vector<std::string> history_columns() const { return {}; }
  virtual std::vector<std::string> history_values() const { return {}; }
};

}  // namespace needle
