#include "solver/separation/lip_release.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/input_error.h"

namespace needle {

const char* lip_release_mode_name(LipReleaseMode mode) {
  switch (mode) {
    case LipReleaseMode::off: return "off";
    case LipReleaseMode::free: return "free";
    case LipReleaseMode::crushed: return "crushed";
  }
  return "?";
}

LipReleaseMode lip_release_mode_from_name(const std::string& name) {
  if (name == "off") return LipReleaseMode::off;
  if (name == "free") return LipReleaseMode::free;
  if (name == "crushed") return LipReleaseMode::crushed;
  throw InputError("must be crushed, free or off (got '" + name + "')");
}

std::string LipReleaseOptions::describe(const LipReleaseOptions& unnamed) const {
  if (mode == unnamed.mode && below_mm == unnamed.below_mm && depth_mm == unnamed.depth_mm) return "";
  if (mode == LipReleaseMode::off) return "the lip below the tip point stays as the tissue is (no lip release)";
  const std::string released = mode == LipReleaseMode::free ? "is cut loose (lip release free)" : "is crushed (lip release)";
  if (whole_lip()) return "the whole lip below the tip point " + released;
  return fmt::format("the tissue the tip meets from {:g} mm below its tip point", below_mm) +
         (std::isfinite(depth_mm) ? fmt::format(" to {:g} mm", below_mm + depth_mm) : std::string(" down to the rod's bottom")) +
         ", inside the rod's outline, " + released;
}

void LipReleaseOptions::validate(const std::string& where) const {
  NEEDLE_REQUIRE(depth_mm > 0, fmt::format("{}: depth_mm must be positive (got {}; leave it out for the whole lip)", where, depth_mm));
  NEEDLE_REQUIRE(std::isfinite(below_mm) && below_mm >= 0, fmt::format("{}: below_mm must be zero or positive (got {})", where, below_mm));
}

namespace {

// The needle's frame as the lip sees it: the tip point A (its most distal node) and the rod's radius about y = z = 0.
struct LipFrame {
  Eigen::Index tip_node = 0;
  Eigen::Vector3d tip_mm = Eigen::Vector3d::Zero();
  double rod_radius_mm = 0;
};

LipFrame lip_frame(const Eigen::MatrixX3d& needle_reference_mm) {
  NEEDLE_REQUIRE(needle_reference_mm.rows() > 0, "lip_release: the needle has no nodes");
  LipFrame f;
  needle_reference_mm.col(0).maxCoeff(&f.tip_node);
  f.tip_mm = needle_reference_mm.row(f.tip_node).transpose();
  f.rod_radius_mm = needle_reference_mm.rightCols<2>().rowwise().norm().maxCoeff();
  return f;
}

}  // namespace

LipRelease::LipRelease(const Eigen::MatrixX3d& needle_reference_mm, const LipReleaseOptions& options) : options_(options) {
  options_.validate();
  const LipFrame f = lip_frame(needle_reference_mm);
  tip_node_ = f.tip_node;
  tip_reference_mm_ = f.tip_mm;
  rod_radius_mm_ = f.rod_radius_mm;
}

double LipRelease::lip_thickness_mm(const Eigen::MatrixX3d& needle_reference_mm) {
  const LipFrame f = lip_frame(needle_reference_mm);
  return f.tip_mm.y() + f.rod_radius_mm;
}

std::vector<std::int32_t> LipRelease::particles_in_band(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x) const {
  std::vector<std::int32_t> found;
  if (!options_.enabled()) return found;
  const Eigen::Vector3d tip = needle_x.row(tip_node_).transpose();
  const Eigen::Vector3d axis = tip - tip_reference_mm_;  // the needle frame's origin moved with A (x unused)
  const double r2 = rod_radius_mm_ * rod_radius_mm_;
  const double top_y = tip.y() - options_.below_mm;
  for (size_t i = 0; i < x.size(); ++i) {
    if (!released_.empty() && released_[i]) continue;
    const Vec3d& p = x[i];
    if (p.x() > tip.x() || p.x() < tip.x() - kWindowBehindMm) continue;
    if (p.y() >= top_y || p.y() < top_y - options_.depth_mm) continue;
    const double dy = p.y() - axis.y(), dz = p.z() - axis.z();
    if (dy * dy + dz * dz <= r2) found.push_back(static_cast<std::int32_t>(i));
  }
  return found;
}

std::vector<std::int64_t> LipRelease::bonds_of(const BondNetwork& bonds, const std::vector<std::int32_t>& particles) {
  std::vector<std::int64_t> found;
  for (const std::int32_t i : particles)
    for (std::int64_t k = bonds.particle_offset[static_cast<size_t>(i)]; k < bonds.particle_offset[static_cast<size_t>(i) + 1]; ++k) {
      const std::int64_t b = bonds.particle_bonds[static_cast<size_t>(k)];
      if (!bonds.bonds[static_cast<size_t>(b)].broken) found.push_back(b);
    }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

std::int64_t LipRelease::release(SpgTissue& tissue, const Eigen::MatrixX3d& needle_x) {
  if (!options_.enabled()) return 0;
  const std::vector<Vec3d>& x = tissue.particles().position_mm;
  if (released_.empty()) released_.assign(x.size(), 0);
  const std::vector<std::int32_t> band = particles_in_band(x, needle_x);
  if (band.empty()) return 0;
  if (options_.mode == LipReleaseMode::free) cut_ += tissue.cut_bonds(bonds_of(tissue.bonds(), band));
  for (const std::int32_t i : band) {
    released_[static_cast<size_t>(i)] = 1;
    if (options_.mode == LipReleaseMode::crushed) tissue.particles().flags[static_cast<size_t>(i)] |= kParticleCrushed;
  }
  released_count_ += static_cast<std::int64_t>(band.size());
  return static_cast<std::int64_t>(band.size());
}

void LipRelease::apply(SpgTissue& tissue, const NeedleModel& needle) {
  const auto start = std::chrono::steady_clock::now();
  release(tissue, needle.positions_mm());
  wall_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void LipRelease::add_summary(nlohmann::json& summary, const SpgTissue&) const {
  summary["lip_release"] = {{"mode", lip_release_mode_name(options_.mode)},
                            {"below_mm", options_.below_mm},
                            {"depth_mm", std::isfinite(options_.depth_mm) ? nlohmann::json(options_.depth_mm) : nlohmann::json(kWholeLipText)},
                            {"lip_thickness_mm", lip_thickness_mm()},
                            {"particles_released", released_count_},
                            {"bonds_cut", cut_},
                            {"lip_release_s", wall_s_}};
}

std::vector<std::string> LipRelease::history_values() const { return {fmt::format("{}", released_count_)}; }

}  // namespace needle
