#include "solver/separation/symmetry_slit.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "mesher/particle_lattice.h"

namespace needle {

std::string SymmetrySlitOptions::describe() const {
  if (!enabled()) return "";
  return fmt::format("the tissue also splits in the symmetry plane behind the tip, {:g} mm either side of the rod's axis", half_height_mm);
}

void SymmetrySlitOptions::validate(const std::string& where) const {
  NEEDLE_REQUIRE(std::isfinite(half_height_mm) && half_height_mm >= 0,
                 fmt::format("{}: half_height_mm must be zero (no slit) or positive (got {})", where, half_height_mm));
  NEEDLE_REQUIRE(std::isfinite(lead_mm) && lead_mm >= 0, fmt::format("{}: lead_mm must be zero or positive (got {})", where, lead_mm));
}

SymmetrySlit::SymmetrySlit(const Eigen::MatrixX3d& needle_reference_mm, const SymmetrySlitOptions& options) : options_(options) {
  options_.validate();
  NEEDLE_REQUIRE(needle_reference_mm.rows() > 0, "slit: the needle has no nodes");
  needle_reference_mm.col(0).maxCoeff(&tip_node_);
  tip_reference_mm_ = needle_reference_mm.row(tip_node_).transpose();
}

std::int64_t SymmetrySlit::open(TissueParticles& particles, const Eigen::MatrixX3d& needle_x) {
  if (!options_.enabled()) return 0;
  const Eigen::Vector3d tip = needle_x.row(tip_node_).transpose();
  const double front_x = tip.x() + options_.lead_mm;
  const double axis_y = tip.y() - tip_reference_mm_.y();  // the rod's axis is y = 0 in the needle's frame
  if (!candidates_listed_) {
    for (std::int64_t i = 0; i < particles.size(); ++i) {
      const std::uint8_t flag = particles.flags[static_cast<size_t>(i)];
      if ((flag & kParticleSymmetry) && !(flag & (kParticleOpenSymmetry | kParticleFixed))) closed_.push_back(static_cast<std::int32_t>(i));
    }
    candidates_listed_ = true;
  }
  size_t kept = 0;  // closed_ keeps the particles still closed, in order
  for (const std::int32_t i : closed_) {
    const Vec3d& x = particles.position_mm[static_cast<size_t>(i)];
    if (x.x() <= front_x && std::abs(x.y() - axis_y) <= options_.half_height_mm)
      particles.flags[static_cast<size_t>(i)] |= kParticleOpenSymmetry;
    else
      closed_[kept++] = i;
  }
  const std::int64_t now = static_cast<std::int64_t>(closed_.size() - kept);
  closed_.resize(kept);
  opened_ += now;
  return now;
}

SymmetrySlit::Opening SymmetrySlit::opening(const SpgTissue& tissue) {
  const TissueParticles& p = tissue.particles();
  Opening o;
  std::int64_t count = 0;
  for (std::int64_t i = 0; i < p.size(); ++i) {
    if (!(p.flags[static_cast<size_t>(i)] & kParticleOpenSymmetry) || !tissue.is_integration_point(i)) continue;
    const double z = p.position_mm[static_cast<size_t>(i)].z();
    o.max_mm = std::max(o.max_mm, z);
    o.mean_mm += z;
    ++count;
  }
  if (count > 0) o.mean_mm /= static_cast<double>(count);
  return o;
}

void SymmetrySlit::add_summary(nlohmann::json& summary, const SpgTissue& tissue) const {
  const Opening o = opening(tissue);
  summary["slit"] = {{"particles_opened", opened_}, {"max_opening_mm", o.max_mm}, {"mean_opening_mm", o.mean_mm}};
}

}  // namespace needle
