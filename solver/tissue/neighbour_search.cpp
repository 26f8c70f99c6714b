#include "solver/tissue/neighbour_search.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "core/input_error.h"
#include "core/parallel.h"

namespace needle {

NeighbourLists find_covering_centres(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& centres,
                                     const KernelSupports& supports) {
  const std::int64_t num_centres = centres.rows(), num_points = points.rows();
  NeighbourLists lists;
  lists.offset.assign(static_cast<size_t>(num_points + 1), 0);
  if (num_points == 0) return lists;
  NEEDLE_REQUIRE(num_centres > 0, "no particles to search");
  NEEDLE_REQUIRE(supports.size() == num_centres, "one kernel support per particle");
  const double cell = supports.largest_mm();
  NEEDLE_REQUIRE(cell > 0 && std::isfinite(cell), "support radius must be a positive length");
  const Eigen::RowVector3d lo = centres.colwise().minCoeff();
  const Eigen::RowVector3d span = centres.colwise().maxCoeff() - lo;
  Eigen::Array3i dims;
  for (int k = 0; k < 3; ++k) dims[k] = std::max(1, static_cast<int>(std::floor(span[k] / cell)) + 1);
  NEEDLE_REQUIRE(static_cast<double>(dims.prod()) < 4e8, "particle cloud too spread out for the cell grid");
  auto cell_of = [&](const Eigen::RowVector3d& p) {
    Eigen::Array3i c;
    for (int k = 0; k < 3; ++k) c[k] = static_cast<int>(std::floor((p[k] - lo[k]) / cell));
    return c;
  };
  // Counting sort of the centres into cells.
  const std::int64_t num_cells = static_cast<std::int64_t>(dims.prod());
  std::vector<std::int64_t> cell_start(static_cast<size_t>(num_cells + 1), 0);
  std::vector<std::int64_t> cell_index(static_cast<size_t>(num_centres));
  for (std::int64_t j = 0; j < num_centres; ++j) {
    const Eigen::Array3i c = cell_of(centres.row(j)).max(0).min(dims - 1);
    cell_index[static_cast<size_t>(j)] = (static_cast<std::int64_t>(c[2]) * dims[1] + c[1]) * dims[0] + c[0];
    ++cell_start[static_cast<size_t>(cell_index[static_cast<size_t>(j)] + 1)];
  }
  for (std::int64_t c = 0; c < num_cells; ++c) cell_start[static_cast<size_t>(c + 1)] += cell_start[static_cast<size_t>(c)];
  std::vector<std::int32_t> sorted(static_cast<size_t>(num_centres));
  {
    std::vector<std::int64_t> fill(cell_start.begin(), cell_start.end() - 1);
    for (std::int64_t j = 0; j < num_centres; ++j)
      sorted[static_cast<size_t>(fill[static_cast<size_t>(cell_index[static_cast<size_t>(j)])]++)] = static_cast<std::int32_t>(j);
  }
  std::vector<std::vector<std::int32_t>> found(static_cast<size_t>(num_points));
  parallel_for(num_points, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const Eigen::RowVector3d p = points.row(i);
      const Eigen::Array3i c = cell_of(p);
      auto& out = found[static_cast<size_t>(i)];
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const Eigen::Array3i q = c + Eigen::Array3i(dx, dy, dz);
            if ((q < 0).any() || (q >= dims).any()) continue;
            const std::int64_t id = (static_cast<std::int64_t>(q[2]) * dims[1] + q[1]) * dims[0] + q[0];
            for (std::int64_t s = cell_start[static_cast<size_t>(id)]; s < cell_start[static_cast<size_t>(id + 1)]; ++s) {
              const std::int32_t j = sorted[static_cast<size_t>(s)];
              if (supports.covers(j, (centres.row(j) - p).transpose())) out.push_back(j);
            }
          }
      std::sort(out.begin(), out.end());
    }
  });
  for (std::int64_t i = 0; i < num_points; ++i)
    lists.offset[static_cast<size_t>(i + 1)] = lists.offset[static_cast<size_t>(i)] + static_cast<std::int64_t>(found[static_cast<size_t>(i)].size());
  lists.index.resize(static_cast<size_t>(lists.offset.back()));
  parallel_for(num_points, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i)
      std::copy(found[static_cast<size_t>(i)].begin(), found[static_cast<size_t>(i)].end(),
                lists.index.begin() + lists.offset[static_cast<size_t>(i)]);
  });
  return lists;
}

}  // namespace needle
