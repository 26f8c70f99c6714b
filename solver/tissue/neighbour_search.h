#pragma once
// Which particle supports cover which points: a uniform cell grid (cell = the largest support
// semi-axis) over the centres, queried per point. Deterministic: each list is sorted by index.
#include <Eigen/Dense>
#include <cstdint>
#include <vector>

#include "solver/tissue/kernel_supports.h"

namespace needle {

// Compressed rows: the centres j covering point i are index[offset[i] .. offset[i+1]).
struct NeighbourLists {
  std::vector<std::int64_t> offset;  // #points + 1
  std::vector<std::int32_t> index;   // centre indices
  std::int64_t rows() const { return static_cast<std::int64_t>(offset.size()) - 1; }
};

// For each point i, every centre j whose support holds it strictly inside (|points_i - centres_j| < radius_j
// for spheres). points: #Q by 3, centres: #P by 3, supports: #P.
NeighbourLists find_covering_centres(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& centres,
                                     const KernelSupports& supports);

}  // namespace needle
