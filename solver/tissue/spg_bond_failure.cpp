// The SPG tissue's bonds breaking (spg_tissue.h): the bonds the failure rule breaks at the end of a step, the shortest
// bond each particle keeps, and the bonds a separation model cuts; SpgTissue::separate (spg_tissue.cpp) then rebuilds
// the kernels without them.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/input_error.h"
#include "core/parallel.h"
#include "solver/tissue/spg_tissue.h"

namespace needle {

std::int64_t SpgTissue::break_bonds() {
  const BondFailure& rule = options_.bond_failure;
  const double rupture_stretch = std::exp(rule.strain);  // the bond's own stretch at the failure strain
  const std::vector<double>& strain = rule.measure == FailureMeasure::plastic_strain ? p_.plastic_strain : p_.effective_strain;
  // Only bonds with an active particle can break. A bond fails on its pair's mean strain (so one of them is
  // above the failure strain), on its stretch beyond `limit` (|x_i - x_j| <= L + d_i + d_j with L its reference
  // length and d a particle's displacement from its reference position: one of them moved more than
  // (limit - 1) L / 2, and L is at least the particle's shortest bond; 1 % kept in hand against rounding), or
  // dead (one of them detached). The others are not looked at: the same bonds break as in a scan of all.
  const double limit = rule.measure == FailureMeasure::effective_strain
                           ? (rule.stretch_ratio > 0 ? std::min(rupture_stretch, rule.stretch_ratio) : rupture_stretch)
                           : rule.stretch_ratio;
  const std::int64_t n = p_.size();
  active_.resize(static_cast<size_t>(n));
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const size_t s = static_cast<size_t>(i);
      active_[s] = !rk_.valid[s] || strain[s] > rule.strain ||
                   (limit > 0 && (p_.position_mm[s] - p_.reference_mm[s]).norm() > 0.99 * (limit - 1) * 0.5 * shortest_bond_mm_[s]);
    }
  });
  std::vector<std::int32_t> candidates;
  for (size_t s = 0; s < active_.size(); ++s)
    if (active_[s])
      for (std::int64_t k = bonds_.particle_offset[s]; k < bonds_.particle_offset[s + 1]; ++k) {
        const std::int32_t b = bonds_.particle_bonds[static_cast<size_t>(k)];
        if (!bonds_.bonds[static_cast<size_t>(b)].broken) candidates.push_back(b);
      }
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  return separate(classify_bonds(bonds_, candidates, [&](const Bond& bond) -> std::uint8_t {
    const size_t i = static_cast<size_t>(bond.i), j = static_cast<size_t>(bond.j);
    // A bond that no integration point uses any more (its entries only in the rows of detached particles)
    // couples nothing: it is separated whatever the strains say (a detached particle's strain is frozen).
    const bool dead = !(bond.entry_ij >= 0 && rk_.valid[i]) && !(bond.entry_ji >= 0 && rk_.valid[j]);
    if (dead) return 2;
    bool fails = 0.5 * (strain[i] + strain[j]) > rule.strain;
    if (rule.measure == FailureMeasure::effective_strain && !fails) {
      // The bond's own log stretch against the same rupture strain: the long, weak bonds at the corner of
      // a support carry almost nothing, so a crack opening past them never raises the particles'
      // strain; measured along the bond they fail with the material around them.
      const double reference = (p_.reference_mm[i] - p_.reference_mm[j]).norm();
      fails = (p_.position_mm[i] - p_.position_mm[j]).norm() > rupture_stretch * reference;
    }
    if (rule.stretch_ratio > 0) {
      const double reference = (p_.reference_mm[i] - p_.reference_mm[j]).norm();
      fails = fails || (p_.position_mm[i] - p_.position_mm[j]).norm() > rule.stretch_ratio * reference;
    }
    return fails ? 1 : 0;
  }));
}

void SpgTissue::update_shortest_bonds() {
  shortest_bond_mm_.assign(static_cast<size_t>(p_.size()), std::numeric_limits<double>::infinity());
  for (const Bond& bond : bonds_.bonds) {
    const double length = (p_.reference_mm[static_cast<size_t>(bond.i)] - p_.reference_mm[static_cast<size_t>(bond.j)]).norm();
    shortest_bond_mm_[static_cast<size_t>(bond.i)] = std::min(shortest_bond_mm_[static_cast<size_t>(bond.i)], length);
    shortest_bond_mm_[static_cast<size_t>(bond.j)] = std::min(shortest_bond_mm_[static_cast<size_t>(bond.j)], length);
  }
}

std::int64_t SpgTissue::cut_bonds(const std::vector<std::int64_t>& bond_indices) {
  std::vector<std::int64_t> sorted = bond_indices;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  std::vector<std::pair<std::int64_t, std::uint8_t>> breaking;
  for (std::int64_t b : sorted)
    if (!bonds_.bonds.at(static_cast<size_t>(b)).broken) breaking.emplace_back(b, std::uint8_t{1});
  const std::int64_t count = separate(breaking);
  bonds_.cut_count += count;
  return count;
}

}  // namespace needle
