#pragma once
// Bonds: the particle pairs that interact, i.e. j in the support covering i or i in the support covering
// j. A bond names its (up to two) shape-function entries; breaking it cuts both, so the pair leaves each
// other's supports and the rows are rebuilt without it.
#include <cstdint>
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

struct BondNetwork {
  std::vector<Bond> bonds;
  std::int64_t broken_count = 0;  // all broken bonds: by the failure criterion, dead, or cut
  std::int64_t cut_count = 0;     // of those, the ones cut by a body through them (SpgTissue::cut_bonds)
};

BondNetwork build_bond_network(const RkShapeFunctions& rk);

// The intact bonds for which selected(bond) holds, in increasing order; tested in parallel (selected must only read).
template <class Selected>
std::vector<std::int64_t> select_intact_bonds(const BondNetwork& bonds, const Selected& selected) {
  const std::int64_t n = static_cast<std::int64_t>(bonds.bonds.size());
  std::vector<std::uint8_t> chosen(static_cast<size_t>(n), 0);
  parallel_for(n, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t b = begin; b < end; ++b) {
      const Bond& bond = bonds.bonds[static_cast<size_t>(b)];
      chosen[static_cast<size_t>(b)] = !bond.broken && selected(bond);
    }
  });
  std::vector<std::int64_t> out;
  for (std::int64_t b = 0; b < n; ++b)
    if (chosen[static_cast<size_t>(b)]) out.push_back(b);
  return out;
}

}  // namespace needle
