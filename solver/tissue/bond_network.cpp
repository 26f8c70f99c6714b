#include "solver/tissue/bond_network.h"

#include <algorithm>
#include <limits>

#include "core/input_error.h"

namespace needle {

BondNetwork build_bond_network(const RkShapeFunctions& rk) {
  BondNetwork network;
  auto find_entry = [&](std::int64_t row, std::int32_t centre) -> std::int64_t {
    const auto first = rk.centre.begin() + rk.offset[static_cast<size_t>(row)];
    const auto last = rk.centre.begin() + rk.offset[static_cast<size_t>(row + 1)];
    const auto it = std::lower_bound(first, last, centre);
    return (it != last && *it == centre) ? static_cast<std::int64_t>(it - rk.centre.begin()) : -1;
  };
  for (std::int64_t i = 0; i < rk.rows(); ++i)
    for (std::int64_t e = rk.offset[static_cast<size_t>(i)]; e < rk.offset[static_cast<size_t>(i + 1)]; ++e) {
      const std::int32_t j = rk.centre[static_cast<size_t>(e)];
      if (j == i) continue;
      if (j > i) {
        network.bonds.push_back({static_cast<std::int32_t>(i), j, e, find_entry(j, static_cast<std::int32_t>(i)), false});
      } else if (find_entry(j, static_cast<std::int32_t>(i)) < 0) {
        // One-sided pair (supports of different size): i sees j, j does not see i.
        network.bonds.push_back({j, static_cast<std::int32_t>(i), -1, e, false});
      }
    }
  std::sort(network.bonds.begin(), network.bonds.end(),
            [](const Bond& a, const Bond& b) { return a.i != b.i ? a.i < b.i : a.j < b.j; });
  network.index(rk.rows());
  return network;
}

void BondNetwork::index(std::int64_t particles) {
  NEEDLE_REQUIRE(bonds.size() < static_cast<size_t>(std::numeric_limits<std::int32_t>::max()),
                 "the tissue has more bonds than 32-bit indices count");
  const size_t n = static_cast<size_t>(particles);
  particle_offset.assign(n + 1, 0);
  intact.clear();
  intact.reserve(bonds.size());
  for (size_t b = 0; b < bonds.size(); ++b) {
    const Bond& bond = bonds[b];
    NEEDLE_REQUIRE(bond.i >= 0 && bond.j >= 0 && static_cast<size_t>(std::max(bond.i, bond.j)) < n, "a bond names a particle that does not exist");
    ++particle_offset[static_cast<size_t>(bond.i) + 1];
    ++particle_offset[static_cast<size_t>(bond.j) + 1];
    if (!bond.broken) intact.push_back({bond.i, bond.j, static_cast<std::int32_t>(b)});
  }
  listed_broken = 0;
  for (size_t i = 0; i < n; ++i) particle_offset[i + 1] += particle_offset[i];
  particle_bonds.resize(2 * bonds.size());
  std::vector<std::int64_t> next(particle_offset.begin(), particle_offset.end() - 1);
  for (size_t b = 0; b < bonds.size(); ++b) {
    particle_bonds[static_cast<size_t>(next[static_cast<size_t>(bonds[b].i)]++)] = static_cast<std::int32_t>(b);
    particle_bonds[static_cast<size_t>(next[static_cast<size_t>(bonds[b].j)]++)] = static_cast<std::int32_t>(b);
  }
}

void BondNetwork::mark_broken(std::int64_t b) {
  bonds[static_cast<size_t>(b)].broken = true;
  if (++listed_broken * 50 <= static_cast<std::int64_t>(intact.size())) return;
  intact.erase(std::remove_if(intact.begin(), intact.end(), [&](const IntactPair& p) { return bonds[static_cast<size_t>(p.bond)].broken; }),
               intact.end());
  listed_broken = 0;
}

}  // namespace needle
