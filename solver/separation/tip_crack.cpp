#include "solver/separation/tip_crack.h"

#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "core/input_error.h"

namespace needle {

std::string TipCrackOptions::describe() const {
  if (!enabled()) return "";
  std::string d = fmt::format("the tip drives a crack past the rod: fins from the tip point at {} deg in the cross-section (0: horizontal), {:g} mm long",
                              fmt::join(angles_deg, ", "), reach_mm);
  if (lead_mm > 0) d += fmt::format(", running {:g} mm ahead of the tip", lead_mm);
  return d;
}

void TipCrackOptions::validate(const std::string& where) const {
  NEEDLE_REQUIRE(std::isfinite(reach_mm) && reach_mm >= 0,
                 fmt::format("{}: reach_mm must be zero (no crack) or positive (got {})", where, reach_mm));
  NEEDLE_REQUIRE(std::isfinite(lead_mm) && lead_mm >= 0, fmt::format("{}: lead_mm must be zero or positive (got {})", where, lead_mm));
  NEEDLE_REQUIRE(!enabled() || !angles_deg.empty(), fmt::format("{}: angles_deg must name at least one fin", where));
  for (const double a : angles_deg)
    NEEDLE_REQUIRE(std::isfinite(a) && a >= -180 && a <= 180,
                   fmt::format("{}: angles_deg must lie in [-180, 180] degrees (got {})", where, a));
}

TipCrack::TipCrack(const Eigen::MatrixX3d& needle_reference_mm, const TipCrackOptions& options) : options_(options) {
  options_.validate();
  NEEDLE_REQUIRE(needle_reference_mm.rows() > 0, "crack: the needle has no nodes");
  needle_reference_mm.col(0).maxCoeff(&tip_node_);
}

std::vector<std::int64_t> TipCrack::bonds_across(const BondNetwork& bonds, const std::vector<Vec3d>& x,
                                                 const Eigen::MatrixX3d& needle_x) const {
  if (!options_.enabled()) return {};
  const Eigen::Vector3d tip = needle_x.row(tip_node_).transpose();
  const double x_lo = tip.x() - kWindowBehindMm, x_hi = tip.x() + options_.lead_mm;
  struct Fin {
    Eigen::Vector3d along, normal;  // u in the cross-section, and e_x x u
  };
  std::vector<Fin> fins;
  for (const double a : options_.angles_deg) {
    const double psi = a * M_PI / 180.0;
    const Eigen::Vector3d u(0, std::sin(psi), std::cos(psi));
    fins.push_back({u, Eigen::Vector3d::UnitX().cross(u)});
  }
  return select_intact_bonds(bonds, [&](std::int32_t i, std::int32_t j) {
    const Vec3d& p = x[static_cast<size_t>(i)];
    const Vec3d& q = x[static_cast<size_t>(j)];
    if (std::max(p.x(), q.x()) < x_lo || std::min(p.x(), q.x()) > x_hi) return false;
    const Eigen::Vector3d a = p - tip, d = q - p;
    for (const Fin& fin : fins) {
      const double da = fin.normal.dot(a), db = fin.normal.dot(a + d);
      if (!(da * db < 0)) continue;  // both ends on one side of the fin's plane, or one on it
      const Eigen::Vector3d hit = a + (da / (da - db)) * d;  // relative to A
      const double r = fin.along.dot(hit);
      if (r >= 0 && r <= options_.reach_mm && tip.x() + hit.x() >= x_lo && tip.x() + hit.x() <= x_hi) return true;
    }
    return false;
  });
}

void TipCrack::apply(SpgTissue& tissue, const NeedleModel& needle) {
  const auto start = std::chrono::steady_clock::now();
  cut_ += tissue.cut_bonds(bonds_across(tissue.bonds(), tissue.particles().position_mm, needle.positions_mm()));
  wall_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void TipCrack::add_summary(nlohmann::json& summary, const SpgTissue&) const {
  summary["crack"] = {{"reach_mm", options_.reach_mm}, {"bonds_cut", cut_}, {"crack_s", wall_s_}};
}

}  // namespace needle
