#include "solver/tissue/tissue_mass_scaling.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

TissueMassScaling::TissueMassScaling(double target_dt_ms, const TissueParticles& particles)
    : target_dt_ms_(target_dt_ms), physical_mass_g_(particles.mass_g) {
  NEEDLE_REQUIRE(std::isfinite(target_dt_ms) && target_dt_ms > 0,
                 fmt::format("the tissue's mass scaling step must be positive (got {} ms)", target_dt_ms));
  for (double m : physical_mass_g_) physical_mass_total_g_ += m;
}

void TissueMassScaling::set_target_dt_ms(double target_dt_ms) {
  NEEDLE_REQUIRE(std::isfinite(target_dt_ms) && target_dt_ms > 0,
                 fmt::format("the tissue's mass scaling step must be positive (got {} ms)", target_dt_ms));
  target_dt_ms_ = target_dt_ms;
}

double TissueMassScaling::time_step_ms(double unscaled_stable_dt_ms) const { return std::max(target_dt_ms_, unscaled_stable_dt_ms); }

const std::vector<std::int32_t>& TissueMassScaling::apply(double dt_ms, const SpgTissue& tissue, TissueParticles& p,
                                                          const std::vector<std::uint8_t>& constrained_mask) {
  tissue.particle_time_steps_ms(particle_dt_ms_, dt_ms);  // exact below dt_ms, where masses are set
  changed_.clear();
  // Particles that need mass now, and those that had it (they may get their physical mass back).
  std::vector<std::int32_t> scaled_now;
  for (size_t i = 0; i < particle_dt_ms_.size(); ++i)
    if (particle_dt_ms_[i] < dt_ms) scaled_now.push_back(static_cast<std::int32_t>(i));
  std::vector<std::int32_t> touched;
  std::set_union(scaled_.begin(), scaled_.end(), scaled_now.begin(), scaled_now.end(), std::back_inserter(touched));
  double energy = 0, added = 0, added_crushed = 0;
  for (std::int32_t i : touched) {
    const size_t s = static_cast<size_t>(i);
    const double ratio = particle_dt_ms_[s] < dt_ms ? (dt_ms / particle_dt_ms_[s]) * (dt_ms / particle_dt_ms_[s]) : 1.0;
    const double m_new = physical_mass_g_[s] * ratio, m_old = p.mass_g[s];
    added += m_new - physical_mass_g_[s];
    report_.max_ratio = std::max(report_.max_ratio, ratio);
    if (p.flags[s] & kParticleCrushed) {
      added_crushed += m_new - physical_mass_g_[s];
      report_.max_ratio_crushed = std::max(report_.max_ratio_crushed, ratio);
    }
    if (m_new == m_old) continue;
    Vec3d& v = p.velocity_mm_per_ms[s];
    const double ke_old = 0.5 * m_old * v.squaredNorm();
    if (m_new > m_old)  // gaining mass: momentum kept (the particle slows); losing it: velocity kept
      for (int axis = 0; axis < 3; ++axis)
        if (!(constrained_mask[s] & (1 << axis))) v[axis] *= m_old / m_new;
    p.mass_g[s] = m_new;
    energy += 0.5 * m_new * v.squaredNorm() - ke_old;
    changed_.push_back(i);
  }
  scaled_.swap(scaled_now);
  report_.scaled_particles = static_cast<std::int64_t>(scaled_.size());
  report_.added_mass_g = added;
  report_.max_added_mass_g = std::max(report_.max_added_mass_g, added);
  report_.max_added_mass_crushed_g = std::max(report_.max_added_mass_crushed_g, added_crushed);
  report_.energy_mJ += energy;
  return changed_;
}

}  // namespace needle
