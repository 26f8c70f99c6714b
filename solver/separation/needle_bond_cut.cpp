#include "solver/separation/needle_bond_cut.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/parallel.h"
#include "solver/separation/needle_cut_grid.h"

namespace needle {

namespace {

Eigen::Vector3d everywhere_lo() { return Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity()); }
Eigen::Vector3d everywhere_hi() { return Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()); }

}  // namespace

NeedleBondCut::NeedleBondCut(const ContactSurface& surface, double candidate_margin_mm, bool certify)
    : surface_(surface), margin_mm_(candidate_margin_mm), certify_(certify && candidate_margin_mm > 0) {}

NeedleBondCut::Grid NeedleBondCut::build_grid(const Eigen::MatrixX3d& needle_x, const Eigen::Vector3d& clip_lo, const Eigen::Vector3d& clip_hi) const {
  Grid grid;
  const Eigen::MatrixX3i& tris = surface_.triangles();
  grid.triangles.reserve(static_cast<size_t>(tris.rows()));
  const Eigen::Vector3d lo = needle_x.colwise().minCoeff(), hi = needle_x.colwise().maxCoeff();
  const double plane_tol = 1e-9 * std::max(1.0, (hi - lo).norm());
  double extent_sum = 0;
  int primaries = 0;
  // A triangle wholly outside the clip box (beyond the tolerance the test widens it by) meets no segment inside it.
  const auto add = [&grid, &clip_lo, &clip_hi](const std::array<Eigen::Vector3d, 3>& v) {
    Grid::Triangle t;
    t.v0 = v[0];
    t.e1 = v[1] - v[0];
    t.e2 = v[2] - v[0];
    t.edge_lengths = t.e1.norm() * t.e2.norm();
    t.lo = v[0].cwiseMin(v[1]).cwiseMin(v[2]).array() - needle_cut::kBoxSlackMm;
    t.hi = v[0].cwiseMax(v[1]).cwiseMax(v[2]).array() + needle_cut::kBoxSlackMm;
    if ((t.hi.array() < clip_lo.array()).any() || (t.lo.array() > clip_hi.array()).any()) return false;
    grid.triangles.push_back(t);
    return true;
  };
  for (Eigen::Index t = 0; t < tris.rows(); ++t) {
    std::array<Eigen::Vector3d, 3> v;
    for (int k = 0; k < 3; ++k) v[static_cast<size_t>(k)] = needle_x.row(tris(t, k)).transpose();
    const Eigen::Vector3d tlo = v[0].cwiseMin(v[1]).cwiseMin(v[2]), thi = v[0].cwiseMax(v[1]).cwiseMax(v[2]);
    if (add(v)) {
      extent_sum += (thi - tlo).maxCoeff();
      ++primaries;
    }
    // The mirror image closes a half model's surface; only triangles on the plane can meet a segment
    // that stays on the model's side (z >= 0).
    if (surface_.half_model() && tlo.z() <= plane_tol) {
      grid.mirrored_signature = grid.mirrored_signature * 1000003u + static_cast<std::uint64_t>(t) + 1;
      std::array<Eigen::Vector3d, 3> m = v;
      for (auto& p : m) p.z() = -p.z();
      add(m);
    }
  }
  if (grid.triangles.empty()) {
    // Nothing to meet: a box that every point lies below, so every segment is passed over.
    grid.lo.setConstant(std::numeric_limits<double>::infinity());
    grid.hi.setConstant(-std::numeric_limits<double>::infinity());
    grid.cells.setOnes();
    grid.start.assign(2, 0);
    grid.near.assign(1, 0);
    return grid;
  }
  grid.cell_mm = std::max(1.5 * extent_sum / std::max(primaries, 1), 1e-3);
  grid.lo = grid.triangles.front().lo;
  grid.hi = grid.triangles.front().hi;
  for (const Grid::Triangle& t : grid.triangles) {
    grid.lo = grid.lo.cwiseMin(t.lo);
    grid.hi = grid.hi.cwiseMax(t.hi);
  }
  grid.lo.array() -= grid.cell_mm;
  grid.hi.array() += grid.cell_mm;
  grid.cells = ((grid.hi - grid.lo) / grid.cell_mm).array().ceil().cast<int>().cwiseMax(1);
  const int count = grid.cells.prod();
  // Each cell's triangles in increasing order (a counting sort: two passes over the triangles' cells).
  const auto for_each_cell = [&grid](const Grid::Triangle& tri, const auto& visit) {
    const Eigen::Vector3i c0 = grid.cell_of(tri.lo);
    const Eigen::Vector3i c1 = grid.cell_of(tri.hi);
    for (int i = c0.x(); i <= c1.x(); ++i)
      for (int j = c0.y(); j <= c1.y(); ++j)
        for (int k = c0.z(); k <= c1.z(); ++k) visit(grid.index(i, j, k));
  };
  grid.start.assign(static_cast<size_t>(count + 1), 0);
  for (const Grid::Triangle& tri : grid.triangles) for_each_cell(tri, [&](int cell) { ++grid.start[static_cast<size_t>(cell + 1)]; });
  for (size_t c = 1; c < grid.start.size(); ++c) grid.start[c] += grid.start[c - 1];
  grid.entries.resize(static_cast<size_t>(grid.start.back()));
  std::vector<int> next(grid.start.begin(), grid.start.end() - 1);
  for (size_t t = 0; t < grid.triangles.size(); ++t)
    for_each_cell(grid.triangles[t], [&](int cell) { grid.entries[static_cast<size_t>(next[static_cast<size_t>(cell)]++)] = static_cast<int>(t); });
  grid.near.assign(static_cast<size_t>(count), 0);
  for (int i = 0; i < grid.cells.x(); ++i)
    for (int j = 0; j < grid.cells.y(); ++j)
      for (int k = 0; k < grid.cells.z(); ++k) {
        const int cell = grid.index(i, j, k);
        if (grid.start[static_cast<size_t>(cell)] == grid.start[static_cast<size_t>(cell + 1)]) continue;
        for (int a = std::max(i - 1, 0); a <= std::min(i + 1, grid.cells.x() - 1); ++a)
          for (int b = std::max(j - 1, 0); b <= std::min(j + 1, grid.cells.y() - 1); ++b)
            for (int c = std::max(k - 1, 0); c <= std::min(k + 1, grid.cells.z() - 1); ++c) grid.near[static_cast<size_t>(grid.index(a, b, c))] = 1;
      }
  return grid;
}

template <class Visit>
void NeedleBondCut::for_each_hit(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Visit& visit, bool* overlapped) const {
  const Eigen::Vector3d lo = a.cwiseMin(b), hi = a.cwiseMax(b);
  if ((hi.array() < grid.lo.array()).any() || (lo.array() > grid.hi.array()).any()) return;
  const Eigen::Vector3i c0 = grid.cell_of(lo), c1 = grid.cell_of(hi);
  // A segment within two cells along each axis (most bonds) lies in the cells around its lowest one: with no
  // triangle there, no crossing, and the cells are not walked. (Cells are clamped to the grid, which only
  // widens what is looked at.)
  if ((c1 - c0).maxCoeff() <= 1 && !grid.near[static_cast<size_t>(grid.index(c0.x(), c0.y(), c0.z()))]) return;
  const Eigen::Vector3d d = b - a;
  const double length = d.norm();
  needle_cut::for_each_triangle_in_cells(grid, c0, c1, [&](const Grid::Triangle& t) {
    if ((hi.array() < t.lo.array()).any() || (lo.array() > t.hi.array()).any()) return true;  // boxes apart: no hit
    if (overlapped) *overlapped = true;
    const double hit = needle_cut::segment_triangle(a, d, length, t);
    return std::isnan(hit) || visit(hit);
  });
}

std::vector<double> NeedleBondCut::crossings(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  std::vector<double> s;
  for_each_hit(grid, a, b, [&s](double hit) {
    s.push_back(hit);
    return true;
  });
  std::sort(s.begin(), s.end());
  s.erase(std::unique(s.begin(), s.end(), [](double x, double y) { return y - x < needle_cut::kDistinctCrossing; }), s.end());
  return s;
}

bool NeedleBondCut::passes_through(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  // crossings() merges each hit into the last one it kept when they are closer than needle_cut::kDistinctCrossing, so it
  // finds two distinct points exactly when its highest and lowest hits lie that far apart: the walk stops there.
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  bool two = false;
  for_each_hit(grid, a, b, [&](double hit) {
    lowest = std::min(lowest, hit);
    highest = std::max(highest, hit);
    two = highest - lowest >= needle_cut::kDistinctCrossing;
    return !two;
  });
  return two;
}

bool NeedleBondCut::passes_through(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b, bool& overlapped) const {
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  bool two = false;
  overlapped = false;
  for_each_hit(grid, a, b, [&](double hit) {
    lowest = std::min(lowest, hit);
    highest = std::max(highest, hit);
    two = highest - lowest >= needle_cut::kDistinctCrossing;
    return !two;
  }, &overlapped);
  return two;
}

std::vector<double> NeedleBondCut::surface_crossings(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                     const Eigen::MatrixX3d& needle_x) const {
  return crossings(build_grid(needle_x, everywhere_lo(), everywhere_hi()), a, b);
}

namespace needle_cut {

// Each particle's side of the box [lo, hi] along each axis (bit 2k: below it on axis k, bit 2k + 1: above): a segment
// whose two ends share a bit lies wholly on that side, which is for_each_hit's first test.
std::vector<std::uint8_t> box_sides(const std::vector<Vec3d>& x, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  std::vector<std::uint8_t> side(x.size());
  parallel_for(static_cast<std::int64_t>(x.size()), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i) {
      const Vec3d& p = x[static_cast<size_t>(i)];
      std::uint8_t bits = 0;
      for (int k = 0; k < 3; ++k) {
        if (p[k] < lo[k]) bits |= static_cast<std::uint8_t>(1 << (2 * k));
        if (p[k] > hi[k]) bits |= static_cast<std::uint8_t>(2 << (2 * k));
      }
      side[static_cast<size_t>(i)] = bits;
    }
  });
  return side;
}

}  // namespace needle_cut

std::vector<std::int64_t> NeedleBondCut::scan(const Grid& grid, const IntactPair* pairs, std::int64_t count, const BondNetwork& bonds,
                                              const std::vector<Vec3d>& x) const {
  // Most bonds are rejected by their sides alone, without their positions.
  const std::vector<std::uint8_t> side = needle_cut::box_sides(x, grid.lo, grid.hi);
  // The arrays are read through local pointers: the compiler cannot tell that appending a find leaves the lists'
  // addresses be, so it would reload them for every pair.
  return parallel_collect_chunks<std::int64_t>(count, [&](std::int64_t begin, std::int64_t end, std::vector<std::int64_t>& found) {
    const Bond* const all = bonds.bonds.data();
    const std::uint8_t* const sides = side.data();
    const Vec3d* const positions = x.data();
    for (std::int64_t k = begin; k < end; ++k) {
      const IntactPair pair = pairs[k];
      if (sides[pair.i] & sides[pair.j]) continue;
      if (!all[pair.bond].broken && passes_through(grid, positions[pair.i], positions[pair.j])) found.push_back(pair.bond);
    }
  });
}

std::vector<std::int64_t> NeedleBondCut::bonds_through_needle(const BondNetwork& bonds, const std::vector<Vec3d>& x,
                                                              const Eigen::MatrixX3d& needle_x) const {
  const Grid grid = build_grid(needle_x, everywhere_lo(), everywhere_hi());
  return scan(grid, bonds.intact.data(), static_cast<std::int64_t>(bonds.intact.size()), bonds, x);
}

std::vector<std::int64_t> NeedleBondCut::bonds_through_needle_tracked(const BondNetwork& bonds, const std::vector<Vec3d>& x,
                                                                      const Eigen::MatrixX3d& needle_x) {
  // One pass over the particles: their box (a bond's segment lies within it, so the needle's triangles outside it, its
  // part still in the cannula early in a run, are left out of the grid) and whether one has moved half the margin
  // along an axis since the list was made.
  const double half = 0.5 * margin_mm_;
  const bool compare = margin_mm_ > 0 && listed_ && listed_x_.size() == x.size();
  bool still = compare;
  Eigen::Vector3d particles_lo = everywhere_hi(), particles_hi = everywhere_lo();
  for (size_t i = 0; i < x.size(); ++i) {
    particles_lo = particles_lo.cwiseMin(x[i]);
    particles_hi = particles_hi.cwiseMax(x[i]);
    if (still) still = (x[i] - listed_x_[i]).cwiseAbs().maxCoeff() < half;
  }
  // With certificates the grid also holds the triangles within reach of a gap (kCertificateReachMm).
  const double reach = certify_ ? kCertificateReachMm : 0.0;
  const Grid grid = build_grid(needle_x, particles_lo.array() - reach, particles_hi.array() + reach);
  if (certify_) track_needle_motion(needle_x, grid.mirrored_signature);
  if (!(margin_mm_ > 0)) return scan(grid, bonds.intact.data(), static_cast<std::int64_t>(bonds.intact.size()), bonds, x);
  // The list holds every bond the step could cut while the box lies within the listed box widened by half the margin
  // and no particle has moved half the margin along an axis: a bond left off had both ends beyond the listed box
  // widened by the whole margin, on one side, and so both still lie beyond the current box on that side.
  const bool valid = still && (grid.lo.array() >= list_lo_.array() + half).all() && (grid.hi.array() <= list_hi_.array() - half).all();
  if (!valid) {
    list_lo_ = grid.lo.array() - margin_mm_;
    list_hi_ = grid.hi.array() + margin_mm_;
    const std::vector<std::uint8_t> side = needle_cut::box_sides(x, list_lo_, list_hi_);
    const IntactPair* const pairs = bonds.intact.data();
    const Bond* const all = bonds.bonds.data();
    candidates_ = parallel_collect_chunks<IntactPair>(static_cast<std::int64_t>(bonds.intact.size()),
                                                      [&](std::int64_t begin, std::int64_t end, std::vector<IntactPair>& found) {
                                                        for (std::int64_t k = begin; k < end; ++k) {
                                                          const IntactPair pair = pairs[k];
                                                          if (!(side[pair.i] & side[pair.j]) && !all[pair.bond].broken) found.push_back(pair);
                                                        }
                                                      });
    listed_x_ = x;
    listed_ = true;
    ++lists_made_;
    if (certify_) {  // every certificate starts anew, so the motion's bound need only keep its last two calls (the rate)
      certificates_.assign(candidates_.size(), Certificate{});
      needle_motion_.erase(needle_motion_.begin(), needle_motion_.end() - std::min<std::ptrdiff_t>(2, static_cast<std::ptrdiff_t>(needle_motion_.size())));
    }
  }
  if (certify_) return scan_certified(grid, bonds, x);
  return scan(grid, candidates_.data(), static_cast<std::int64_t>(candidates_.size()), bonds, x);
}

void NeedleBondCut::apply(SpgTissue& tissue, const NeedleModel& needle) {
  const auto start = std::chrono::steady_clock::now();
  cut_ += tissue.cut_bonds(bonds_through_needle_tracked(tissue.bonds(), tissue.particles().position_mm, needle.positions_mm()));
  wall_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void NeedleBondCut::add_summary(nlohmann::json& summary, const SpgTissue&) const {
  summary["bonds_cut_by_needle"] = cut_;
  summary["bond_cut_s"] = wall_s_;
  summary["bond_cut_candidate_lists"] = lists_made_;
  summary["bond_cut_tests"] = {{"made", tests_made_}, {"skipped_on_certificate", tests_skipped_}};
}

}  // namespace needle
