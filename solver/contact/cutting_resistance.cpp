#include "solver/contact/cutting_resistance.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "core/input_error.h"

namespace needle {

std::string CuttingOptions::describe() const {
  if (!enabled()) return "";
  return fmt::format("cutting the tissue costs work: a pressure of {:g} MPa on the tip facets that advance into it", pressure_MPa);
}

void CuttingOptions::validate(const std::string& where) const {
  NEEDLE_REQUIRE(std::isfinite(pressure_MPa) && pressure_MPa >= 0,
                 fmt::format("{}: cutting_pressure_MPa must be zero or positive (got {})", where, pressure_MPa));
}

CuttingResistance::CuttingResistance(const ContactSurface& surface, const TissueParticles& particles, const CuttingOptions& options)
    : surface_(surface), options_(options) {
  options_.validate();
  // The tip's ground facets all face forward (their outward normals have n_x = sin(theta) > 0 in the CAD
  // frame), which orients each triangle whatever its winding.
  const Eigen::MatrixX3d& X = surface_.reference_positions();
  const Eigen::MatrixX3i& tri = surface_.triangles();
  orientation_.assign(static_cast<size_t>(surface_.num_triangles()), 0.0);
  double half_spacing = 0;
  for (size_t i = 0; i < static_cast<size_t>(particles.size()); ++i) {
    block_.extend(particles.position_mm[i]);
    half_spacing = std::max(half_spacing, 0.5 * particles.spacing_mm[i]);
  }
  block_.min().array() -= half_spacing;
  block_.max().array() += half_spacing;
  for (int t = 0; t < surface_.num_triangles(); ++t) {
    const std::string& tag = surface_.tag_names()[static_cast<size_t>(surface_.triangle_tag(t))];
    if (std::find(options_.facets.begin(), options_.facets.end(), tag) == options_.facets.end()) continue;
    const Eigen::Vector3d a = X.row(tri(t, 0)), b = X.row(tri(t, 1)), c = X.row(tri(t, 2));
    orientation_[static_cast<size_t>(t)] = (b - a).cross(c - a).x() >= 0 ? 1.0 : -1.0;
    triangles_.push_back(t);
  }
  NEEDLE_REQUIRE(!triangles_.empty(), fmt::format("contact: a cutting pressure needs a needle with tip facets; the surface has none of the tags {}",
                                                  fmt::join(options_.facets, ", ")));
  facets_.assign(surface_.tag_names().size(), FacetContact{});
}

void CuttingResistance::needle_forces(const Eigen::MatrixX3d& needle_x, const Eigen::MatrixX3d& needle_v, double time_ms, NodalForces& out) {
  const Eigen::MatrixX3i& tri = surface_.triangles();
  const double pressure = options_.pressure_MPa;
  facets_.assign(surface_.tag_names().size(), FacetContact{});
  force_on_needle_N_.setZero();
  force_N_ = 0;
  double power = 0;
  for (int t : triangles_) {
    const Eigen::Vector3d a = needle_x.row(tri(t, 0)), b = needle_x.row(tri(t, 1)), c = needle_x.row(tri(t, 2));
    if (!block_.contains((a + b + c) / 3.0)) continue;
    const Eigen::Vector3d area_normal = 0.5 * orientation_[static_cast<size_t>(t)] * (b - a).cross(c - a);  // A n
    const Eigen::Vector3d v = (needle_v.row(tri(t, 0)) + needle_v.row(tri(t, 1)) + needle_v.row(tri(t, 2))).transpose() / 3.0;
    const double advance = area_normal.dot(v);  // A n . v
    if (!(advance > 0)) continue;               // only where the facet moves into the tissue
    const Eigen::Vector3d f = -pressure * area_normal;
    for (int k = 0; k < 3; ++k) out.emplace_back(tri(t, k), f / 3.0);
    FacetContact& facet = facets_[static_cast<size_t>(surface_.triangle_tag(t))];
    facet.normal_N += pressure * area_normal.norm();
    facet.force_N += f;
    facet.cutting_force_N += f;
    force_on_needle_N_ += f;
    force_N_ += pressure * area_normal.norm();
    power += pressure * advance;
  }
  const double dt = time_ms - last_eval_ms_;
  if (dt > 0) work_mJ_ += 0.5 * dt * (last_power_mW_ + power);
  last_power_mW_ = power;
  last_eval_ms_ = time_ms;
}

void CuttingResistance::add_to(ContactReport& report) const {
  for (size_t k = 0; k < facets_.size() && k < report.facets.size(); ++k) {
    report.facets[k].normal_N += facets_[k].normal_N;
    report.facets[k].force_N += facets_[k].force_N;
    report.facets[k].cutting_force_N += facets_[k].cutting_force_N;
  }
  report.force_on_needle_N += force_on_needle_N_;
  report.cutting_force_N += force_N_;
}

void CuttingResistance::add_summary(nlohmann::json& summary) const {
  summary["cutting"] = {{"pressure_MPa", options_.pressure_MPa}, {"work_mJ", work_mJ_}, {"force_at_end_N", force_N_}};
}

}  // namespace needle
