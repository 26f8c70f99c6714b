#include "solver/contact/needle_tissue_contact.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/input_error.h"
#include "core/parallel.h"

namespace needle {

void ContactOptions::validate(const std::string& where) const {
  NEEDLE_REQUIRE(std::isfinite(friction) && friction >= 0, fmt::format("{}: friction must be zero or positive (got {})", where, friction));
  NEEDLE_REQUIRE(std::isfinite(stiffness_factor) && stiffness_factor > 0 && stiffness_factor <= 1e4,
                 fmt::format("{}: stiffness_factor must be in (0, 1e4] (got {})", where, stiffness_factor));
  NEEDLE_REQUIRE(std::isfinite(skin_mm) && skin_mm >= 0, fmt::format("{}: skin_mm must be zero or positive (got {})", where, skin_mm));
  NEEDLE_REQUIRE(std::isfinite(damping_ratio) && damping_ratio >= 0 && damping_ratio <= 1,
                 fmt::format("{}: damping_ratio must be in [0, 1] (got {})", where, damping_ratio));
  NEEDLE_REQUIRE(std::isfinite(needle_stiffness_scale) && needle_stiffness_scale > 0 && needle_stiffness_scale <= 0.5,
                 fmt::format("{}: needle_stiffness_scale must be in (0, 0.5] (got {})", where, needle_stiffness_scale));
  NEEDLE_REQUIRE(std::isfinite(voxel_mm) && voxel_mm >= 1e-3 && voxel_mm <= 0.2,
                 fmt::format("{}: voxel_mm must be in [0.001, 0.2] (got {})", where, voxel_mm));
}

NeedleTissueContact::NeedleTissueContact(const ContactSurface& surface, const TissueParticles& particles,
                                         const TissueMaterial& material, const ContactOptions& options)
    : surface_(surface), options_(options) {
  options_.validate();
  const size_t n = static_cast<size_t>(particles.size());
  stiffness_.resize(n);
  mass_ = particles.mass_g;
  stable_dt_ms_ = std::numeric_limits<double>::infinity();
  // The penalty follows the tissue at a strain the needle imposes (1): the elastic modulus for the
  // paper's card, the stiffened tangent for a stiffening law.
  const double modulus = material.tangent_p_wave_modulus_MPa(1.0);
  for (size_t i = 0; i < n; ++i) {
    const double h = particles.spacing_mm[i];
    stiffness_[i] = options_.stiffness_factor * modulus * particles.reference_volume_mm3[i] / (h * h);
    stable_dt_ms_ = std::min(stable_dt_ms_, 2 * std::sqrt(mass_[i] / stiffness_[i]));
  }
  node_cell_mm_ = surface_.node_search_radius_mm();
}

void NeedleTissueContact::set_needle(const Eigen::VectorXd& nodal_mass_g, double time_step_ms) {
  NEEDLE_REQUIRE(nodal_mass_g.size() == surface_.reference_positions().rows(), "contact: one needle mass per node");
  NEEDLE_REQUIRE(time_step_ms > 0, "contact: the needle's step must be positive");
  needle_mass_ = nodal_mass_g;
  needle_dt_ms_ = time_step_ms;
}

void NeedleTissueContact::build_node_grid(const Eigen::MatrixX3d& x) {
  const std::vector<int>& nodes = surface_.nodes();
  box_lo_ = box_hi_ = x.row(nodes.front()).transpose();
  for (int n : nodes) {
    box_lo_ = box_lo_.cwiseMin(x.row(n).transpose());
    box_hi_ = box_hi_.cwiseMax(x.row(n).transpose());
  }
  node_origin_ = box_lo_.array() - 2 * node_cell_mm_;
  node_cells_.clear();
  for (int n : nodes) {
    const Eigen::Vector3i c = ((x.row(n).transpose() - node_origin_) / node_cell_mm_).array().floor().cast<int>();
    node_cells_.emplace_back((static_cast<long>(c.x()) << 42) | (static_cast<long>(c.y()) << 21) | c.z(), n);
  }
  std::sort(node_cells_.begin(), node_cells_.end());
}

int NeedleTissueContact::nearest_surface_node(const Eigen::Vector3d& p, const Eigen::MatrixX3d& x) const {
  const Eigen::Vector3i c = ((p - node_origin_) / node_cell_mm_).array().floor().cast<int>();
  int best = -1;
  double best_d2 = node_cell_mm_ * node_cell_mm_;
  for (int i = c.x() - 1; i <= c.x() + 1; ++i)
    for (int j = c.y() - 1; j <= c.y() + 1; ++j)
      for (int k = c.z() - 1; k <= c.z() + 1; ++k) {
        if (i < 0 || j < 0 || k < 0) continue;
        const long key = (static_cast<long>(i) << 42) | (static_cast<long>(j) << 21) | k;
        auto it = std::lower_bound(node_cells_.begin(), node_cells_.end(), std::make_pair(key, -1));
        for (; it != node_cells_.end() && it->first == key; ++it) {
          const double d2 = (x.row(it->second).transpose() - p).squaredNorm();
          if (d2 < best_d2) {
            best_d2 = d2;
            best = it->second;
          }
        }
      }
  return best;
}

void NeedleTissueContact::probe(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x, const std::vector<double>& reach) {
  build_node_grid(needle_x);
  double max_reach = 0;
  for (double r : reach) max_reach = std::max(max_reach, r);
  const double margin = node_cell_mm_ + options_.skin_mm + max_reach;
  const Eigen::Vector3d lo = box_lo_.array() - margin, hi = box_hi_.array() + margin;
  const NeedleLevelSet& level_set = surface_.level_set();
  const Eigen::MatrixX3i& tri = surface_.triangles();
  const Eigen::MatrixX3d& X0 = surface_.reference_positions();
  const double skin = options_.skin_mm;
  probes_.resize(x.size());
  parallel_for(static_cast<std::int64_t>(x.size()), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      Probe& probe = probes_[s];
      probe = Probe{};
      const Eigen::Vector3d p = x[s];
      if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
      const int node = nearest_surface_node(p, needle_x);
      if (node < 0) continue;
      const Eigen::Vector3d X = surface_.pull_back(p, node, needle_x);
      const double phi = level_set.signed_distance_mm(X);
      probe.phi = phi;
      probe.inside = phi < 0;
      if (phi >= skin + reach[s]) continue;
      Eigen::Vector3d normal = level_set.gradient(X);
      if (!(normal.norm() > 1e-6)) continue;  // outside the band: farther than any reach
      normal.normalize();
      Pair& pair = probe.pair;
      pair.particle = static_cast<int>(i);
      const SurfacePoint at = surface_.locate(X - phi * normal);
      if (at.triangle >= 0) {
        pair.triangle = at.triangle;
        pair.weights = at.weights;
        // Turn the reference normal with the triangle under the point.
        const auto corner = [&](const Eigen::MatrixX3d& m, int k) { return m.row(tri(at.triangle, k)).transpose().eval(); };
        const Eigen::Vector3d n_ref = (corner(X0, 1) - corner(X0, 0)).cross(corner(X0, 2) - corner(X0, 0)).normalized();
        const Eigen::Vector3d n_cur =
            (corner(needle_x, 1) - corner(needle_x, 0)).cross(corner(needle_x, 2) - corner(needle_x, 0)).normalized();
        if (n_ref.allFinite() && n_cur.allFinite()) normal = (normal + n_cur - n_ref).normalized();
      } else {
        pair.node = node;
      }
      pair.normal = normal;
      pair.particle_start = p;
      pair.surface_start = surface_point(pair, needle_x);
      pair.gap_start = skin - phi;
      probe.near = true;
    }
  });
}

Eigen::Vector3d NeedleTissueContact::surface_point(const Pair& pair, const Eigen::MatrixX3d& needle) const {
  if (pair.triangle < 0) return needle.row(pair.node).transpose();
  const Eigen::MatrixX3i& tri = surface_.triangles();
  return pair.weights[0] * needle.row(tri(pair.triangle, 0)).transpose() + pair.weights[1] * needle.row(tri(pair.triangle, 1)).transpose() +
         pair.weights[2] * needle.row(tri(pair.triangle, 2)).transpose();
}

InsideReport NeedleTissueContact::classify(const TissueParticles& particles, const Eigen::MatrixX3d& needle_x) {
  probe(particles.position_mm, needle_x, std::vector<double>(static_cast<size_t>(particles.size()), 0.0));
  InsideReport r;
  for (size_t i = 0; i < probes_.size(); ++i) {
    const Probe& p = probes_[i];
    if (p.inside) {
      ++r.particles_inside;
      r.max_depth_mm = std::max(r.max_depth_mm, -p.phi);
    }
  }
  return r;
}

void NeedleTissueContact::begin_step(const TissueParticles& particles, const Eigen::MatrixX3d& needle_x, const Eigen::MatrixX3d& needle_v,
                                     double start_time_ms, double dt_ms) {
  NEEDLE_REQUIRE(dt_ms > 0, "contact: a step needs a positive length");
  const size_t n = static_cast<size_t>(particles.size());
  double needle_speed = 0;
  for (int node : surface_.nodes()) needle_speed = std::max(needle_speed, needle_v.row(node).norm());
  std::vector<Vec3d> start(n);
  std::vector<double> reach(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3d& v = particles.velocity_mm_per_ms[i];
    start[i] = particles.position_mm[i] - dt_ms * v;
    // Whatever can close the gap within the step, with room to spare.
    reach[i] = 1.5 * dt_ms * (v.norm() + needle_speed) + 0.25 * options_.skin_mm;
  }
  probe(start, needle_x, reach);
  pairs_.clear();
  report_.particles_inside = 0;
  report_.max_depth_mm = 0;
  for (size_t i = 0; i < n; ++i) {
    const Probe& p = probes_[i];
    if (p.inside) {
      ++report_.particles_inside;
      report_.max_depth_mm = std::max(report_.max_depth_mm, -p.phi);
    }
    if (!p.near) continue;
    Pair& pair = pairs_.emplace_back(p.pair);
    pair.particle_velocity = particles.velocity_mm_per_ms[i];
    // The law's constants over the step. The needle's mass at the contact point, by the force's weights,
    // caps the stiffness on its side and enters the damper's reduced mass and the friction cap.
    const Eigen::MatrixX3i& tri = surface_.triangles();
    double needle_mass = std::numeric_limits<double>::infinity();
    if (needle_mass_.size() > 0)
      needle_mass = pair.triangle >= 0 ? pair.weights[0] * needle_mass_[tri(pair.triangle, 0)] + pair.weights[1] * needle_mass_[tri(pair.triangle, 1)] +
                                             pair.weights[2] * needle_mass_[tri(pair.triangle, 2)]
                                       : needle_mass_[pair.node];
    const bool rigid = !std::isfinite(needle_dt_ms_);
    pair.stiffness = rigid ? stiffness_[i]
                           : std::min(stiffness_[i], options_.needle_stiffness_scale * needle_mass / (needle_dt_ms_ * needle_dt_ms_));
    const double reduced_mass = std::isfinite(needle_mass) ? mass_[i] * needle_mass / (mass_[i] + needle_mass) : mass_[i];
    pair.damping = options_.damping_ratio * 2 * std::sqrt(pair.stiffness * reduced_mass);
    // The viscous cap: friction may not reverse the sliding within either body's step.
    pair.friction_cap = 0.5 * std::min(mass_[i] / dt_ms, rigid ? mass_[i] / dt_ms : needle_mass / needle_dt_ms_);
  }
  // The penalty energy jumps where the geometry is found anew (the gap was linearised over the last step).
  double penalty_now = 0;
  for (const Pair& pair : pairs_)
    if (pair.gap_start > 0) penalty_now += 0.5 * pair.stiffness * pair.gap_start * pair.gap_start;
  if (start_time_ms > 0) relinearisation_energy_mJ_ += penalty_now - report_.penalty_energy_mJ;
  pair_force_.assign(pairs_.size(), Eigen::Vector3d::Zero());
  pair_elastic_force_.assign(pairs_.size(), Eigen::Vector3d::Zero());
  pair_dissipative_impulse_.assign(pairs_.size(), Eigen::Vector3d::Zero());
  step_start_ms_ = start_time_ms;
  step_dt_ms_ = dt_ms;
  last_eval_ms_ = std::max(last_eval_ms_, start_time_ms);
}

void NeedleTissueContact::needle_forces(const Eigen::MatrixX3d& needle_x, const Eigen::MatrixX3d& needle_v, double time_ms,
                                        std::vector<std::pair<int, Eigen::Vector3d>>& out) {
  const double tau = time_ms - step_start_ms_, dt = time_ms - last_eval_ms_;
  const Eigen::MatrixX3i& tri = surface_.triangles();
  const double mu = options_.friction;
  report_.particles_in_contact = 0;
  report_.penalty_energy_mJ = 0;
  report_.force_on_needle_N.setZero();
  report_.facets.assign(surface_.tag_names().size(), FacetContact{});
  double friction_power = 0;
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const Pair& pair = pairs_[k];
    Eigen::Vector3d& f = pair_force_[k];
    Eigen::Vector3d& f_elastic = pair_elastic_force_[k];
    f.setZero();
    f_elastic.setZero();
    const Eigen::Vector3d surface_now = surface_point(pair, needle_x);
    const double gap = pair.gap_start - pair.normal.dot(tau * pair.particle_velocity - (surface_now - pair.surface_start));
    if (gap <= 0) continue;
    const double kn = pair.stiffness;
    const Eigen::Vector3d v_rel = pair.particle_velocity - surface_point(pair, needle_v);
    const double approach = v_rel.dot(pair.normal);  // > 0: separating
    const double fn = std::max(0.0, kn * gap - pair.damping * approach);
    friction_power -= (fn - kn * gap) * approach;  // the damper's share: -f_d . v_n >= 0
    f = fn * pair.normal;
    f_elastic = kn * gap * pair.normal;
    const Eigen::Vector3d v_t = v_rel - v_rel.dot(pair.normal) * pair.normal;
    const double speed = v_t.norm();
    double ft = 0;
    if (speed > 0 && mu > 0) {
      ft = std::min(mu * fn, pair.friction_cap * speed);
      f -= ft * v_t / speed;
    }
    friction_power += ft * speed;
    // The dissipative part (damper and friction) as the needle receives it over its substep.
    if (dt > 0) pair_dissipative_impulse_[k] += dt * (f - f_elastic);
    if (pair.triangle >= 0) {
      for (int c = 0; c < 3; ++c) out.emplace_back(tri(pair.triangle, c), -pair.weights[c] * f);
      FacetContact& facet = report_.facets[static_cast<size_t>(surface_.triangle_tag(pair.triangle))];
      ++facet.particles;
      facet.normal_N += fn;
      facet.friction_N += ft;
      facet.force_N -= f;
    } else {
      out.emplace_back(pair.node, -f);
    }
    ++report_.particles_in_contact;
    report_.penalty_energy_mJ += 0.5 * kn * gap * gap;
    report_.force_on_needle_N -= f;
  }
  report_.cutting_force_N = 0;
  report_.friction_power_mW = friction_power;
  if (dt > 0) friction_dissipation_mJ_ += 0.5 * dt * (last_friction_power_mW_ + friction_power);
  if (tau == 0) {  // the state at a step's start (t = 0, before any step): the particles get the forces as they are
    previous_force_.clear();
    previous_particles_.clear();
    for (size_t k = 0; k < pairs_.size(); ++k)
      if (pair_force_[k].squaredNorm() > 0) {
        previous_force_.push_back(pair_force_[k]);
        previous_particles_.push_back(pairs_[k].particle);
      }
    record_contacts();
  }
  last_friction_power_mW_ = friction_power;
  last_eval_ms_ = time_ms;
}

void NeedleTissueContact::end_step(std::vector<Vec3d>& particle_force) {
  NEEDLE_REQUIRE(last_eval_ms_ >= step_start_ms_ + step_dt_ms_ - 1e-9 * std::max(step_dt_ms_, std::abs(step_start_ms_)),
                 fmt::format("contact: the step ended at {} ms before the needle reached its end {} + {} ms", last_eval_ms_, step_start_ms_,
                             step_dt_ms_));
  // The particles get the penalty at the step's end and the dissipative forces as the needle received
  // them over the step (their mean): friction follows the needle's vibration within the step, which one
  // sample at the end would alias. The elastic part must not lag (see the header); the dissipative part may.
  previous_force_.clear();
  previous_particles_.clear();
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const Eigen::Vector3d f = pair_elastic_force_[k] + pair_dissipative_impulse_[k] / step_dt_ms_;
    if (f.squaredNorm() == 0) continue;
    previous_force_.push_back(f);
    previous_particles_.push_back(pairs_[k].particle);
  }
  record_contacts();
  last_particle_forces(particle_force);
}

void NeedleTissueContact::record_contacts() {
  contacts_.clear();
  for (size_t k = 0; k < pairs_.size(); ++k)
    if (pair_force_[k].squaredNorm() > 0) contacts_.emplace_back(pairs_[k].particle, pairs_[k].triangle);
}

void NeedleTissueContact::last_particle_forces(std::vector<Vec3d>& particle_force) const {
  particle_force.assign(stiffness_.size(), Vec3d::Zero());
  for (size_t k = 0; k < previous_force_.size(); ++k) particle_force[static_cast<size_t>(previous_particles_[k])] = previous_force_[k];
}

std::vector<std::uint8_t> NeedleTissueContact::in_contact() const {
  std::vector<std::uint8_t> flags(stiffness_.size(), 0);
  for (const auto& [p, triangle] : contacts_) flags[static_cast<size_t>(p)] = 1;
  return flags;
}

std::vector<Eigen::Vector3d> NeedleTissueContact::pull_back(const std::vector<Vec3d>& x, const Eigen::MatrixX3d& needle_x) {
  build_node_grid(needle_x);
  std::vector<Eigen::Vector3d> out(x.size(), Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  parallel_for(static_cast<std::int64_t>(x.size()), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      const Eigen::Vector3d p = x[s];
      if ((p.array() < box_lo_.array() - node_cell_mm_).any() || (p.array() > box_hi_.array() + node_cell_mm_).any()) continue;
      const int node = nearest_surface_node(p, needle_x);
      if (node >= 0) out[s] = surface_.pull_back(p, node, needle_x);
    }
  });
  return out;
}


}  // namespace needle
