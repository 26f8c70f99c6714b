#include "solver/tissue/bond_network.h"

#include <algorithm>

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
  return network;
}

}  // namespace needle
