#pragma once
// Multi-rate (asynchronous) stepping of the tissue: most particles step far below their own stable step, because
// a few squeezed particles under the needle, or the fine band's, set everybody's. Here each particle gets a level
// k, the largest with 2^k base steps within its own stable step over a safety factor (SpgTissue::particle_time_steps_ms,
// which holds the Courant factor already), at most max_level; particles the caller names fast (near the needle) get 0. A
// point (integration point) takes the fastest level in its row and updates its stress every 2^k base steps; its
// forces then act on its row as the impulse of its whole period (SpgTissue::set_rate_levels). This is an
// asynchronous variational integrator (Lew, Marsden, Ortiz and West 2003) in velocity Verlet form: the base step
// is velocity Verlet with the impulse-weighted forces, so
//   - momentum is kept exactly (each point's forces sum to zero over its row, whatever its period);
//   - every point at level 0 it is velocity Verlet (to rounding: the weighted sums run in another order); without
//     levels (TissueDynamics::set_rate_levels(0), the scene's 0) the integrator is the plain one, bit for bit;
//   - a point between its updates adds nothing, and the particles drift at their velocities.
// The levels are set anew every cycle of 2^max_level base steps, when every point has just been updated; within a
// cycle the base step may shrink (the end time) but not grow. Its error (the far field's stresses sampled
// coarsely) is measured, not assumed: tests/solver/test_tissue_rate_levels.cpp (energy, a wave crossing the rates,
// momentum) and docs/insertion.md.
#include <cstdint>
#include <vector>

#include "solver/tissue/spg_tissue.h"

namespace needle {

class TissueRateLevels {
 public:
  // max_level in [1, 10]: the slowest points update every 2^max_level base steps. safety >= 1: a particle's period
  // is at most its own stable step over this factor (a margin for the squeezing a cycle may bring).
  explicit TissueRateLevels(int max_level, double safety = 1.0);

  int max_level() const { return max_level_; }
  double safety() const { return safety_; }
  std::int64_t cycle_steps() const { return std::int64_t{1} << max_level_; }
  // Particles held at the base rate from the next cycle on (one flag per particle; empty: none).
  void set_fast_particles(std::vector<std::uint8_t> fast) { fast_ = std::move(fast); }
  // Each particle's level for a cycle of base step base_dt_ms, from the tissue's current state.
  const std::vector<std::uint8_t>& levels(const SpgTissue& tissue, double base_dt_ms);

  // Over the base steps so far: the mean share of the points updated in a step (1 at one rate).
  void record_point_levels(const std::vector<std::uint8_t>& point_level);  // the tissue's, once the cycle's levels are set
  void count_step();
  double mean_point_update_share() const { return steps_ > 0 ? update_share_sum_ / static_cast<double>(steps_) : 1.0; }
  // The share of the points at each level in the last cycle (index: level).
  const std::vector<double>& last_point_level_shares() const { return level_shares_; }

 private:
  int max_level_;
  double safety_;
  std::vector<std::uint8_t> fast_, levels_;
  std::vector<double> particle_dt_ms_;
  std::vector<double> level_shares_;
  double cycle_share_ = 1.0, update_share_sum_ = 0;
  std::int64_t steps_ = 0;
};

}  // namespace needle
