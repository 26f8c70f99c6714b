#pragma once
// Bonds: the particle pairs that interact, i.e. j in the support covering i or i in the support covering
// j. A bond names its (up to two) shape-function entries; breaking it cuts both, so the pair leaves each
// other's supports and the rows are rebuilt without it.
#include <cstdint>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "solver/tissue/rk_shape_functions.h"

namespace needle {

struct Bond {
  std::int32_t i, j;          // i < j
  std::int64_t entry_ij = -1;  // entry of centre j in row i (-1: none)
  std::int64_t entry_ji = -1;  // entry of centre i in row j
  bool broken = false;
};

// An intact bond's two particles, compact, for the scans that test every intact bond each step.
struct IntactPair {
  std::int32_t i, j, bond;
};

struct BondNetwork {
  std::vector<Bond> bonds;
  std::int64_t broken_count = 0;  // all broken bonds: by the failure criterion, dead, or cut
  std::int64_t cut_count = 0;     // of those, the ones cut by a body through them (SpgTissue::cut_bonds)
  // Each particle's bonds (CSR, increasing bond index): a bond is listed under both its particles.
  std::vector<std::int64_t> particle_offset;
  std::vector<std::int32_t> particle_bonds;
  // The pairs of the intact bonds in increasing bond order, 12 bytes each where a Bond is 32: a bond broken
  // since the last compaction is still listed (its Bond says broken); mark_broken compacts now and then.
  std::vector<IntactPair> intact;
  std::int64_t listed_broken = 0;

  // Builds the particle lists and the pair list from `bonds` (build_bond_network does; a network made by hand
  // calls it), for this many particles.
  void index(std::int64_t particles);
  // Marks bond b broken (it must be intact) and compacts the pair list once a fiftieth of it is broken.
  void mark_broken(std::int64_t b);
};

BondNetwork build_bond_network(const RkShapeFunctions& rk);

// The intact bonds whose pair (i, j) satisfies selected(i, j), in increasing order: a parallel scan of the
// compact pair list (selected must only read).
template <class Selected>
std::vector<std::int64_t> select_intact_bonds(const BondNetwork& bonds, const Selected& selected) {
  return parallel_collect<std::int64_t>(static_cast<std::int64_t>(bonds.intact.size()), [&](std::int64_t k, std::vector<std::int64_t>& found) {
    const IntactPair& pair = bonds.intact[static_cast<size_t>(k)];
    if (selected(pair.i, pair.j) && !bonds.bonds[static_cast<size_t>(pair.bond)].broken) found.push_back(pair.bond);
  });
}

// The bonds of a sorted list (intact ones) for which kind(bond) is not 0, with that kind, in the list's order;
// tested in parallel (kind must only read).
template <class Kind>
std::vector<std::pair<std::int64_t, std::uint8_t>> classify_bonds(const BondNetwork& bonds, const std::vector<std::int32_t>& listed,
                                                                  const Kind& kind) {
  using Found = std::pair<std::int64_t, std::uint8_t>;
  return parallel_collect<Found>(static_cast<std::int64_t>(listed.size()), [&](std::int64_t k, std::vector<Found>& found) {
    const std::int64_t b = listed[static_cast<size_t>(k)];
    if (const std::uint8_t c = kind(bonds.bonds[static_cast<size_t>(b)])) found.emplace_back(b, c);
  });
}

}  // namespace needle
