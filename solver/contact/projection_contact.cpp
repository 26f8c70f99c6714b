#include "solver/contact/projection_contact.h"

#include <algorithm>
#include <cmath>

#include "core/input_error.h"

namespace needle {

ProjectionContact::ProjectionContact(const ContactSurface& surface, const TissueParticles& particles, const ContactOptions& options)
    : NeedleTissueContact(surface, particles, options) {}

void ProjectionContact::begin_step(const TissueParticles&, const Eigen::MatrixX3d&, const Eigen::MatrixX3d&, double, double dt_ms) {
  NEEDLE_REQUIRE(dt_ms > 0, "contact: a step needs a positive length");
  step_dt_ms_ = dt_ms;
  // The pending reaction as forces over this step, summed per node in the order the nodes first appear.
  const Eigen::MatrixX3i& tri = surface_.triangles();
  std::vector<int> slot(static_cast<size_t>(surface_.reference_positions().rows()), -1);
  pending_force_.clear();
  const auto add = [&](int node, const Eigen::Vector3d& f) {
    int& k = slot[static_cast<size_t>(node)];
    if (k < 0) {
      k = static_cast<int>(pending_force_.size());
      pending_force_.emplace_back(node, Eigen::Vector3d::Zero());
    }
    pending_force_[static_cast<size_t>(k)].second += f;
  };
  for (const Reaction& r : pending_) {
    const Eigen::Vector3d f = r.impulse / dt_ms;
    if (r.pair.triangle >= 0)
      for (int c = 0; c < 3; ++c) add(tri(r.pair.triangle, c), r.pair.weights[c] * f);
    else
      add(r.pair.node, f);
  }
}

void ProjectionContact::needle_forces(const Eigen::MatrixX3d&, const Eigen::MatrixX3d&, double, NodalForces& out) {
  out.insert(out.end(), pending_force_.begin(), pending_force_.end());
}

void ProjectionContact::end_step(TissueDynamics& tissue, const Eigen::MatrixX3d& needle_x, const Eigen::MatrixX3d& needle_v,
                                 std::vector<Vec3d>& particle_force) {
  NEEDLE_REQUIRE(step_dt_ms_ > 0, "contact: end_step without begin_step");
  const double dt = step_dt_ms_;
  const TissueParticles& particles = tissue.particles();
  const size_t n = static_cast<size_t>(particles.size());
  // The work of the reaction the needle received over this step: force times its points' displacement.
  double needle_work = 0;
  for (const Reaction& r : pending_) needle_work += (r.impulse / dt).dot(surface_point(r.pair, needle_x) - r.point_start);

  // Which particles lie within the skin of the needle at the step's end, and their impulses.
  probe(particles.position_mm, needle_x, std::vector<double>(n, 0.0));
  const double mu = options_.friction;
  std::vector<std::pair<std::int32_t, Vec3d>> impulses;
  std::vector<size_t> probe_of;  // the probe of each impulse
  for (size_t k = 0; k < probes_.size(); ++k) {
    const Probe& p = probes_[k];
    const size_t i = static_cast<size_t>(p.index);
    if (!p.near || !(p.pair.gap_start > 0) || (particles.flags[i] & kParticleFixed)) continue;
    const Pair& pair = p.pair;
    const double m = particles.mass_g[i];  // with the tissue's mass scaling, the scaled mass
    const Eigen::Vector3d jn = (m * pair.gap_start / dt) * pair.normal;
    const Eigen::Vector3d v_rel = particles.velocity_mm_per_ms[i] + jn / m - surface_point(pair, needle_v);
    const Eigen::Vector3d v_t = v_rel - v_rel.dot(pair.normal) * pair.normal;
    const double speed = v_t.norm();
    Eigen::Vector3d j = jn;
    if (speed > 0 && mu > 0) j -= std::min(mu * jn.norm(), m * speed) / speed * v_t;
    impulses.emplace_back(static_cast<std::int32_t>(i), j);
    probe_of.push_back(k);
  }
  const double particle_work = tissue.apply_impulses(impulses);  // constrained components dropped from J
  particle_work_mJ_ += particle_work;
  needle_work_mJ_ += needle_work;
  friction_dissipation_mJ_ -= particle_work + needle_work;

  // The reaction, pending for the next step; the report books it as the force at this step's end.
  std::vector<Reaction> next;
  next.reserve(impulses.size());
  clear_report_forces();
  contacts_.clear();
  NodalForces unused;
  for (size_t k = 0; k < impulses.size(); ++k) {
    const Pair& pair = probes_[probe_of[k]].pair;
    const Eigen::Vector3d on_needle = -impulses[k].second;
    next.push_back({pair, on_needle, surface_point(pair, needle_x)});
    const double normal = std::abs(on_needle.dot(pair.normal));
    book_needle_force(pair, on_needle / dt, normal / dt, (on_needle + normal * pair.normal).norm() / dt, unused);
    unused.clear();
    contacts_.emplace_back(pair.particle, pair.triangle);
  }
  pending_.swap(next);
  report_.friction_power_mW = -(particle_work + needle_work) / dt;

  // The check: the moved particles against the needle where it is.
  std::vector<Vec3d> moved(impulses.size());
  for (size_t k = 0; k < impulses.size(); ++k) moved[k] = particles.position_mm[static_cast<size_t>(impulses[k].first)];
  probe(moved, needle_x, std::vector<double>(moved.size(), 0.0), /*same_needle=*/true, &check_probes_);
  report_.particles_inside = 0;
  report_.max_depth_mm = 0;
  for (const Probe& p : check_probes_)
    if (p.inside) {
      ++report_.particles_inside;
      report_.max_depth_mm = std::max(report_.max_depth_mm, -p.phi);
    }
  particle_force.assign(n, Vec3d::Zero());
}

void ProjectionContact::last_particle_forces(std::vector<Vec3d>& particle_force) const {
  particle_force.assign(mass_.size(), Vec3d::Zero());
}

Eigen::Vector3d ProjectionContact::pending_impulse() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Reaction& r : pending_) sum += r.impulse;
  return sum;
}

}  // namespace needle
