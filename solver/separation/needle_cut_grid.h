#pragma once
// The needle's cut, inside: the grid of the needle's current triangles its searches walk, the exact segment test, and
// what needle_bond_cut.cpp and needle_cut_certificates.cpp share (solver/separation/needle_bond_cut.h says what they do).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "solver/separation/needle_bond_cut.h"

namespace needle {

// The needle's current triangles (for a half model with the mirror images of those that touch the
// symmetry plane) binned in a uniform grid over their bounding box: CSR over cells.
struct NeedleBondCut::Grid {
  // A triangle as the segment test reads it: a corner, its two edges from there, the product of their lengths
  // (the scale of the test for parallel segments) and its bounding box, widened by the test's tolerance.
  struct Triangle {
    Eigen::Vector3d v0, e1, e2, lo, hi;
    double edge_lengths = 0;
  };
  std::vector<Triangle> triangles;
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  Eigen::Vector3i cells = Eigen::Vector3i::Zero();
  double cell_mm = 1;
  std::vector<int> start, entries;
  std::vector<std::uint8_t> near;  // per cell: 1 when the cell or one of its 26 neighbours holds a triangle
  std::uint64_t mirrored_signature = 0;  // which triangles a half model mirrors (a hash of their indices)

  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    Eigen::Vector3i c = ((p - lo) / cell_mm).array().floor().cast<int>();
    return c.cwiseMax(0).cwiseMin(cells - Eigen::Vector3i::Ones());
  }
  int index(int i, int j, int k) const { return (i * cells.y() + j) * cells.z() + k; }
};

namespace needle_cut {

inline constexpr double kBarycentricTolerance = 1e-9;  // a segment through a shared edge or the seam still hits
inline constexpr double kDistinctCrossing = 1e-7;      // crossings closer than this (in s) are the same point
inline constexpr double kBoxSlackMm = 1e-6;            // a triangle's box is widened by this before the exact test

// Parameter s in [0, 1] where a + s (b - a) meets triangle t (Moeller-Trumbore), or NaN; length = |b - a|.
template <class Triangle>
inline double segment_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& d, double length, const Triangle& t) {
  const Eigen::Vector3d& e1 = t.e1;
  const Eigen::Vector3d& e2 = t.e2;
  const Eigen::Vector3d q = d.cross(e2);
  const double det = e1.dot(q);
  const double scale = t.edge_lengths * length;
  if (!(std::abs(det) > 1e-12 * scale)) return std::nan("");  // parallel to the triangle's plane
  const double inv = 1.0 / det;
  const Eigen::Vector3d w = a - t.v0;
  const double u = w.dot(q) * inv;
  if (u < -kBarycentricTolerance || u > 1 + kBarycentricTolerance) return std::nan("");
  const Eigen::Vector3d r = w.cross(e1);
  const double v = d.dot(r) * inv;
  if (v < -kBarycentricTolerance || u + v > 1 + kBarycentricTolerance) return std::nan("");
  const double s = e2.dot(r) * inv;
  if (s < -kBarycentricTolerance || s > 1 + kBarycentricTolerance) return std::nan("");
  return std::clamp(s, 0.0, 1.0);
}

// Calls visit(t) for each triangle entered in the cells c0 to c1 (a triangle entered in several cells is visited once
// for each), until visit returns false; returns whether the walk ran to its end.
template <class Visit>
bool for_each_triangle_in_cells(const NeedleBondCut::Grid& grid, const Eigen::Vector3i& c0, const Eigen::Vector3i& c1, const Visit& visit) {
  for (int i = c0.x(); i <= c1.x(); ++i)
    for (int j = c0.y(); j <= c1.y(); ++j)
      for (int k = c0.z(); k <= c1.z(); ++k) {
        const int cell = grid.index(i, j, k);
        for (int e = grid.start[static_cast<size_t>(cell)]; e < grid.start[static_cast<size_t>(cell + 1)]; ++e)
          if (!visit(grid.triangles[static_cast<size_t>(grid.entries[static_cast<size_t>(e)])])) return false;
      }
  return true;
}

// Each particle's side of the box [lo, hi] along each axis (bit 2k: below it on axis k, bit 2k + 1: above): a segment
// whose two ends share a bit lies wholly on that side, which is for_each_hit's first test.
std::vector<std::uint8_t> box_sides(const std::vector<Vec3d>& x, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

}  // namespace needle_cut
}  // namespace needle
