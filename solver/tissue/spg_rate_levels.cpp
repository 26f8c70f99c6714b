// The SPG tissue's force gather and its multi-rate stepping (spg_tissue.h, tissue_rate_levels.h): the forces on the
// particles from the points due at a step, each weighted by its period, and the levels that say which are due.
#include <algorithm>

#include "core/input_error.h"
#include "core/parallel.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {
namespace {

// out[s] = the smallest of level[s] and level[index[k]] over s's entries k in [offset[s], offset[s + 1]).
void fastest_over(const std::vector<std::uint8_t>& level, const std::vector<std::int64_t>& offset, const std::vector<std::int32_t>& index,
                  std::vector<std::uint8_t>& out) {
  const std::int64_t n = static_cast<std::int64_t>(level.size());
  out.resize(level.size());
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      std::uint8_t fastest = level[s];
      for (std::int64_t k = offset[s]; k < offset[s + 1]; ++k) fastest = std::min(fastest, level[static_cast<size_t>(index[static_cast<size_t>(k)])]);
      out[s] = fastest;
    }
  });
}

}  // namespace

void SpgTissue::gather_forces(std::int64_t begin, std::int64_t end, std::int64_t rate_step, bool all_due) {
  const bool penalty = options_.stabilization == Stabilization::penalty;
  if (!multirate()) {
    for (std::int64_t j = begin; j < end; ++j) {
      const size_t s = static_cast<size_t>(j);
      Vec3d f = penalty ? Vec3d(-stiffness_[s] * defect_[s]) : Vec3d::Zero();
      for (std::int64_t c = rk_.column_offset[s]; c < rk_.column_offset[s + 1]; ++c) {
        const size_t i = static_cast<size_t>(rk_.column_row[static_cast<size_t>(c)]);
        const std::array<double, 4>& value = rk_.column_value[static_cast<size_t>(c)];  // psi, grad
        f.noalias() -= piola_volume_[i] * Vec3d(value[1], value[2], value[3]);
        if (penalty) f += stiffness_[i] * value[0] * defect_[i];
      }
      p_.force_N[s] = f;
    }
    return;
  }
  // Each due point's share counts 2^level times: the impulse of its period (a point's penalty term on its own
  // particle is its share too).
  for (std::int64_t j = begin; j < end; ++j) {
    const size_t s = static_cast<size_t>(j);
    Vec3d f = Vec3d::Zero();
    if (all_due || rate_step % (std::int64_t{1} << gather_level_[s]) == 0) {
      if (penalty && (all_due || point_due(s, rate_step))) f = -static_cast<double>(std::int64_t{1} << point_level_[s]) * stiffness_[s] * defect_[s];
      for (std::int64_t c = rk_.column_offset[s]; c < rk_.column_offset[s + 1]; ++c) {
        const size_t i = static_cast<size_t>(rk_.column_row[static_cast<size_t>(c)]);
        if (!all_due && !point_due(i, rate_step)) continue;
        const double weight = static_cast<double>(std::int64_t{1} << point_level_[i]);
        const std::array<double, 4>& value = rk_.column_value[static_cast<size_t>(c)];  // psi, grad
        Vec3d share = -(piola_volume_[i] * Vec3d(value[1], value[2], value[3]));
        if (penalty) share += stiffness_[i] * value[0] * defect_[i];
        f += weight * share;
      }
    }
    p_.force_N[s] = f;
  }
}

void SpgTissue::set_rate_levels(const std::vector<std::uint8_t>& particle_level) {
  const std::int64_t n = p_.size();
  NEEDLE_REQUIRE(ahead_dt_ms_ < 0, "set_rate_levels: points were updated ahead for a step not taken yet");
  NEEDLE_REQUIRE(rate_cycle_complete(), "set_rate_levels: some points lag the tissue's time (the last cycle is not complete)");
  if (particle_level.empty()) {
    point_level_.clear();
    gather_level_.clear();
    point_time_ms_.clear();
    parallel_for(n, [&](std::int64_t begin, std::int64_t end) { gather_forces(begin, end, 0, true); });
    return;
  }
  NEEDLE_REQUIRE(particle_level.size() == static_cast<size_t>(n), "set_rate_levels: one level per particle");
  for (std::uint8_t level : particle_level) NEEDLE_REQUIRE(level < 31, "set_rate_levels: a level above 30");
  // A point's level: the fastest in its row; a particle's gather level: the fastest point in its column.
  fastest_over(particle_level, rk_.offset, rk_.centre, point_level_);
  fastest_over(point_level_, rk_.column_offset, rk_.column_row, gather_level_);
  point_time_ms_.assign(static_cast<size_t>(n), time_ms_);
  max_point_level_ = *std::max_element(point_level_.begin(), point_level_.end());
  rate_step_ = 0;
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) { gather_forces(begin, end, 0, true); });
}

bool SpgTissue::rate_cycle_complete() const {
  return !multirate() || rate_step_ % (std::int64_t{1} << max_point_level_) == 0;
}

}  // namespace needle
