#pragma once
// The fired cannula's edge separates the tissue (solver/insertion/cannula_firing.h): after each step, the intact bonds
// that cross the tube's mid-wall cylinder behind its front are cut, so the tissue inside the bore parts from the tissue
// outside it. Its history columns are the front's position in the needle's reference frame and the bonds cut so far.
#include <chrono>
#include <cstdint>

#include "solver/insertion/cannula_firing.h"
#include "solver/separation/separation_model.h"

namespace needle {

class CannulaEdgeCut : public SeparationModel {
 public:
  // The firing must outlive this model.
  explicit CannulaEdgeCut(const CannulaFiring& firing) : firing_(firing) {}
  std::string name() const override { return "cannula_edge"; }
  void apply(SpgTissue& tissue, const NeedleModel& needle) override;
  void add_summary(nlohmann::json& summary, const SpgTissue& tissue) const override;
  std::vector<std::string> history_columns() const override { return {"cannula_front_x_mm", "cannula_bonds_cut"}; }
  std::vector<std::string> history_values() const override;
  std::int64_t bonds_cut() const { return cut_; }

 private:
  const CannulaFiring& firing_;
  std::int64_t cut_ = 0;
  double wall_s_ = 0, time_ms_ = 0;
};

}  // namespace needle
