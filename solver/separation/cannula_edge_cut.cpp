#include "solver/separation/cannula_edge_cut.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace needle {

void CannulaEdgeCut::apply(SpgTissue& tissue, const NeedleModel& needle) {
  time_ms_ = needle.time_ms();
  if (!firing_.active(time_ms_)) return;
  const auto start = std::chrono::steady_clock::now();
  cut_ += tissue.cut_bonds(firing_.bonds_across(tissue.bonds(), tissue.particles().position_mm, needle.positions_mm(), time_ms_));
  wall_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void CannulaEdgeCut::add_summary(nlohmann::json& summary, const SpgTissue&) const {
  summary["cannula_edge"] = {{"bonds_cut", cut_}, {"cut_s", wall_s_}};
}

std::vector<std::string> CannulaEdgeCut::history_values() const {
  return {fmt::format("{:.6g}", firing_.stroke().front_x_mm(time_ms_)), std::to_string(cut_)};
}

}  // namespace needle
