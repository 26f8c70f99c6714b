#include "solver/insertion/cannula_firing.h"

#include <algorithm>
#include <fmt/format.h>

#include "core/input_error.h"
#include "core/parallel.h"

namespace needle {

void CannulaFiringOptions::validate(const std::string& where) const {
  NEEDLE_REQUIRE(std::isfinite(speed_mm_per_ms) && speed_mm_per_ms > 0, fmt::format("{}: speed must be positive (got {})", where, speed_mm_per_ms));
  NEEDLE_REQUIRE(std::isnan(throw_mm) || (std::isfinite(throw_mm) && throw_mm > 0),
                 fmt::format("{}: throw_mm must be positive, or left out for the groove's far end (got {})", where, throw_mm));
  NEEDLE_REQUIRE(std::isfinite(dwell_ms) && dwell_ms >= 0, fmt::format("{}: dwell_ms must be zero or positive (got {})", where, dwell_ms));
  NEEDLE_REQUIRE(std::isfinite(lead_in_mm) && lead_in_mm >= 0, fmt::format("{}: lead_in_mm must be zero or positive (got {})", where, lead_in_mm));
  NEEDLE_REQUIRE(std::isfinite(tissue_mass_scaling_dt_ms) && tissue_mass_scaling_dt_ms >= 0,
                 fmt::format("{}: tissue_mass_scaling_dt_ms must be zero (the insertion's) or positive (got {})", where, tissue_mass_scaling_dt_ms));
  NEEDLE_REQUIRE(std::isfinite(edge_taper_mm) && edge_taper_mm >= 0,
                 fmt::format("{}: edge_taper_mm must be zero or positive (got {})", where, edge_taper_mm));
}

std::string CannulaFiringOptions::describe() const {
  if (!enabled) return "";
  std::string d = fmt::format("the cannula fired over the groove at {:g} m/s", speed_mm_per_ms);
  d += std::isnan(throw_mm) ? " to the groove's far end" : fmt::format(", a {:g} mm throw", throw_mm);
  if (dwell_ms > 0) d += fmt::format(" after {:g} ms", dwell_ms);
  return d;
}

double CannulaStroke::front_x_mm(double time_ms) const {
  return std::min(stop_x_mm, start_x_mm + speed_mm_per_ms * std::max(0.0, time_ms - start_time_ms));
}

CannulaFiring::CannulaFiring(const CannulaTube& tube, const CannulaStroke& stroke, NeedleAxisFrame frame)
    : tube_(tube), stroke_(stroke), frame_(std::move(frame)) {
  NEEDLE_REQUIRE(tube.inner_radius_mm > 0 && tube.outer_radius_mm > tube.inner_radius_mm, "cannula firing: the wall needs 0 < r_in < r_out");
  NEEDLE_REQUIRE(tube.edge_taper_mm >= 0, "cannula firing: the edge's bevel must be zero or positive");
  NEEDLE_REQUIRE(stroke.speed_mm_per_ms > 0 && stroke.stop_x_mm >= stroke.start_x_mm, "cannula firing: the stroke must move forward");
}

std::vector<Eigen::Vector3d> CannulaFiring::reference_points(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x) const {
  frame_.update(needle_x);
  std::vector<Eigen::Vector3d> out(x.size());
  parallel_for(static_cast<std::int64_t>(x.size()), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) out[static_cast<size_t>(i)] = frame_.to_reference(x[static_cast<size_t>(i)]);
  });
  return out;
}

void CannulaFiring::faces_at(double x_mm, double front_x_mm, double& inner_mm, double& outer_mm) const {
  const double behind = front_x_mm - x_mm;
  const double share = tube_.edge_taper_mm > 0 ? std::min(1.0, behind / tube_.edge_taper_mm) : 1.0;
  const double mid = tube_.mid_radius_mm();
  inner_mm = mid - share * (mid - tube_.inner_radius_mm);
  outer_mm = mid + share * (tube_.outer_radius_mm - mid);
}

void CannulaFiring::push_tissue(TissueDynamics& tissue, const Eigen::MatrixX3d& needle_x, double time_ms, double dt_ms) {
  if (!active(time_ms)) return;
  const double front = stroke_.front_x_mm(time_ms);
  const TissueParticles& p = tissue.particles();
  const std::vector<Eigen::Vector3d> X = reference_points(p.position_mm, needle_x);
  using Impulse = std::pair<std::int32_t, Vec3d>;
  std::vector<Impulse> impulses = parallel_collect<Impulse>(p.size(), [&](std::int64_t i, std::vector<Impulse>& found) {
    const Eigen::Vector3d& P = X[static_cast<size_t>(i)];
    if (P.x() < stroke_.start_x_mm || P.x() > front) return;
    const double r = std::hypot(P.y(), P.z());
    double inner = 0, outer = 0;
    faces_at(P.x(), front, inner, outer);
    if (!(r > inner && r < outer)) return;
    const double push = r <= tube_.mid_radius_mm() ? inner - r : outer - r;
    const Vec3d radial(0, P.y() / r, P.z() / r);
    found.emplace_back(static_cast<std::int32_t>(i), (p.mass_g[static_cast<size_t>(i)] * push / dt_ms) * radial);
  });
  for (const Impulse& impulse : impulses)
    max_push_mm_ = std::max(max_push_mm_, impulse.second.norm() * dt_ms / p.mass_g[static_cast<size_t>(impulse.first)]);
  pushes_ += static_cast<std::int64_t>(impulses.size());
  if (!impulses.empty()) work_mJ_ += tissue.apply_impulses(impulses);
}

std::vector<std::int64_t> CannulaFiring::bonds_across(const BondNetwork& bonds, const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x,
                                                      double time_ms) const {
  if (!active(time_ms)) return {};
  const double front = stroke_.front_x_mm(time_ms), start = stroke_.start_x_mm, R = tube_.mid_radius_mm();
  const std::vector<Eigen::Vector3d> X = reference_points(x, needle_x);
  return select_intact_bonds(bonds, [&](std::int32_t i, std::int32_t j) {
    const Eigen::Vector3d& P = X[static_cast<size_t>(i)];
    const Eigen::Vector3d d = X[static_cast<size_t>(j)] - P;
    if (std::max(P.x(), P.x() + d.x()) < start || std::min(P.x(), P.x() + d.x()) > front) return false;
    // |P_perp + s d_perp| = R for s in (0, 1): a s^2 + b s + c = 0.
    const double a = d.y() * d.y() + d.z() * d.z();
    if (!(a > 0)) return false;
    const double b = 2 * (P.y() * d.y() + P.z() * d.z()), c = P.y() * P.y() + P.z() * P.z() - R * R;
    const double disc = b * b - 4 * a * c;
    if (!(disc > 0)) return false;
    const double root = std::sqrt(disc);
    for (const double s : {(-b - root) / (2 * a), (-b + root) / (2 * a)}) {
      if (!(s > 0 && s < 1)) continue;
      const double hit_x = P.x() + s * d.x();
      if (hit_x >= start && hit_x <= front) return true;
    }
    return false;
  });
}

std::vector<std::uint8_t> CannulaFiring::inside_bore(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x, double time_ms) const {
  std::vector<std::uint8_t> inside(x.size(), 0);
  if (!active(time_ms)) return inside;
  const double front = stroke_.front_x_mm(time_ms), R = tube_.mid_radius_mm();
  const std::vector<Eigen::Vector3d> X = reference_points(x, needle_x);
  for (size_t i = 0; i < X.size(); ++i)
    inside[i] = X[i].x() >= stroke_.start_x_mm && X[i].x() <= front && std::hypot(X[i].y(), X[i].z()) < R;
  return inside;
}

}  // namespace needle
