#include "solver/tissue/tissue_rate_levels.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

TissueRateLevels::TissueRateLevels(int max_level, double safety) : max_level_(max_level), safety_(safety) {
  NEEDLE_REQUIRE(max_level >= 1 && max_level <= 10, fmt::format("the tissue's rate levels must lie in [1, 10] (0: one rate), got {}", max_level));
  NEEDLE_REQUIRE(std::isfinite(safety) && safety >= 1, fmt::format("the tissue's rate safety factor must be at least 1, got {}", safety));
}

const std::vector<std::uint8_t>& TissueRateLevels::levels(const SpgTissue& tissue, double base_dt_ms) {
  const std::int64_t n = tissue.particles().size();
  NEEDLE_REQUIRE(base_dt_ms > 0 && std::isfinite(base_dt_ms), "the tissue's rate levels need a positive base step");
  NEEDLE_REQUIRE(fast_.empty() || fast_.size() == static_cast<size_t>(n), "the particles held fast need one flag per particle");
  // Exact only below the slowest period: above it a particle is at the top level whatever its step.
  tissue.particle_time_steps_ms(particle_dt_ms_, base_dt_ms * static_cast<double>(cycle_steps()));
  levels_.resize(static_cast<size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) {
    const size_t s = static_cast<size_t>(i);
    int level = 0;
    if (fast_.empty() || !fast_[s]) {
      const double ratio = particle_dt_ms_[s] / (safety_ * base_dt_ms);
      level = ratio >= static_cast<double>(cycle_steps()) ? max_level_ : ratio >= 1 ? static_cast<int>(std::floor(std::log2(ratio))) : 0;
      level = std::clamp(level, 0, max_level_);
    }
    levels_[s] = static_cast<std::uint8_t>(level);
  }
  return levels_;
}

void TissueRateLevels::record_point_levels(const std::vector<std::uint8_t>& point_level) {
  level_shares_.assign(static_cast<size_t>(max_level_ + 1), 0.0);
  double share = 0;
  for (std::uint8_t level : point_level) {
    level_shares_[std::min<size_t>(level, level_shares_.size() - 1)] += 1;
    share += std::ldexp(1.0, -static_cast<int>(level));
  }
  const double n = std::max<double>(1.0, static_cast<double>(point_level.size()));
  for (double& s : level_shares_) s /= n;
  cycle_share_ = share / n;
}

void TissueRateLevels::count_step() {
  ++steps_;
  update_share_sum_ += cycle_share_;
}

}  // namespace needle
