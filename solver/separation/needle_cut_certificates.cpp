// The needle's cut: the certificates that let a bond's test be skipped (solver/separation/needle_bond_cut.h).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include "core/parallel.h"
#include "solver/separation/needle_bond_cut.h"
#include "solver/separation/needle_cut_grid.h"

namespace needle {

namespace {

// The box a certificate looks within is widened along each axis by the needle's motion there over kCertificateSteps
// steps, at least kMinDilationMm and at most kCertificateReachMm; no gap exceeds the latter, and the grid holds the
// triangles within that of the particles' box, so a triangle left out lies apart by more. Gaps are taken
// kCertificateSafetyMm short (rounding at the cells' faces); the tissue's own motion, which the needle's does not
// bound, counts as kParticleRateMm a step when the longest-lasting gaps are chosen.
constexpr double kCertificateSteps = 8;
constexpr double kMinDilationMm = 0.01;
constexpr double kCertificateSafetyMm = 1e-9;
constexpr double kParticleRateMm = 1e-4;
constexpr double kPlaneSafetyMm = 1e-6;  // a segment this near a triangle's plane gets no certificate from it

// How many steps the gaps last when each axis closes at its speed: until the first one closes.
double steps_lasting(const Eigen::Vector3d& gap, const Eigen::Vector3d& speed) { return gap.cwiseQuotient(speed).minCoeff(); }

// See passes_through_or_certify: whether the segment a-b lies on one side of the triangle's plane by more than
// kPlaneSafetyMm, and if so the gaps lowered so that their motion along its normal stays below that distance.
template <class Triangle>
bool certify_by_plane(const Triangle& t, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& speed,
                      Eigen::Vector3d& gap) {
  const Eigen::Vector3d normal = t.e1.cross(t.e2);
  const double norm = normal.norm();
  if (!(norm > 0)) return false;
  const Eigen::Vector3d unit = normal / norm;
  const double da = unit.dot(a - t.v0), db = unit.dot(b - t.v0);
  const double distance = da > 0 && db > 0 ? std::min(da, db) : da < 0 && db < 0 ? std::min(-da, -db) : 0.0;
  const double room = distance - kPlaneSafetyMm;
  if (!(room > 0)) return false;
  const Eigen::Vector3d weight = unit.cwiseAbs();
  const double along = weight.dot(gap);
  if (along <= room) return true;
  Eigen::Vector3d best = gap * (room / along);
  double best_steps = steps_lasting(best, speed);
  for (int axis = 0; axis < 3; ++axis) {
    if (!(weight[axis] > 0)) continue;
    Eigen::Vector3d lowered = gap;
    lowered[axis] = (room - (along - weight[axis] * gap[axis])) / weight[axis];
    if (!(lowered[axis] > 0)) continue;
    const double steps = steps_lasting(lowered, speed);
    if (steps > best_steps) {
      best_steps = steps;
      best = lowered;
    }
  }
  gap = best;
  return true;
}

}  // namespace

bool NeedleBondCut::passes_through_or_certify(const Grid& grid, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& dilation,
                                              const Eigen::Vector3d& rate, Eigen::Vector3d& gap) const {
  const Eigen::Vector3d lo = a.cwiseMin(b), hi = a.cwiseMax(b);
  const auto finish = [&gap](bool certified) {
    if (certified) gap.array() -= kCertificateSafetyMm;
    else gap.setZero();
    return false;
  };
  // Wholly beside the grid's box along an axis: every triangle's box lies at least that far apart along it.
  gap.setConstant(kCertificateReachMm);
  bool outside = false;
  for (int k = 0; k < 3; ++k) {
    const double apart = std::max(grid.lo[k] - hi[k], lo[k] - grid.hi[k]);
    if (apart > 0) {
      gap[k] = std::min(gap[k], apart);
      outside = true;
    }
  }
  if (outside) return finish(true);
  const Eigen::Vector3i c0 = grid.cell_of(lo), c1 = grid.cell_of(hi);
  if ((c1 - c0).maxCoeff() <= 1 && !grid.near[static_cast<size_t>(grid.index(c0.x(), c0.y(), c0.z()))]) {
    // No triangle in the 27 cells around c0, which hold the segment: every triangle's box lies beyond a face of that
    // block, so apart along that face's axis by at least the segment's distance to it (a side the grid ends on has none).
    for (int k = 0; k < 3; ++k) {
      double apart = kCertificateReachMm;
      if (c0[k] > 0) apart = std::min(apart, lo[k] - (grid.lo[k] + (c0[k] - 1) * grid.cell_mm));
      if (c0[k] + 1 < grid.cells[k] - 1) apart = std::min(apart, grid.lo[k] + (c0[k] + 2) * grid.cell_mm - hi[k]);
      gap[k] = apart;
    }
    return finish(true);
  }
  // The triangles whose boxes overlap the segment's are tested as passes_through tests them; the others lie apart
  // along some axis, and each lowers the gap along one axis to its own separation there unless it is already
  // covered: the axis whose lowered gaps last the most steps at the rates given.
  gap = dilation.cwiseMin(Eigen::Vector3d::Constant(kCertificateReachMm));
  const Eigen::Vector3d speed = rate.cwiseMax(Eigen::Vector3d::Constant(kParticleRateMm));
  const Eigen::Vector3i d0 = grid.cell_of(lo - gap), d1 = grid.cell_of(hi + gap);
  const Eigen::Vector3d d = b - a;
  const double length = d.norm();
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  bool certified = true;
  const bool walked = needle_cut::for_each_triangle_in_cells(grid, d0, d1, [&](const Grid::Triangle& t) {
    const Eigen::Vector3d apart = (t.lo - hi).cwiseMax(lo - t.hi);
    if ((apart.array() > 0).any()) {  // boxes apart: no hit
      if (!certified || (apart.array() >= gap.array()).any()) return true;
      int best = -1;
      double best_steps = -1;
      for (int axis = 0; axis < 3; ++axis) {
        if (!(apart[axis] > 0)) continue;
        Eigen::Vector3d lowered = gap;
        lowered[axis] = apart[axis];
        const double steps = steps_lasting(lowered, speed);
        if (steps > best_steps) {
          best_steps = steps;
          best = axis;
        }
      }
      gap[best] = apart[best];
      return true;
    }
    // Boxes overlapping: a segment wholly on one side of the triangle's plane cannot meet it, and stays apart while the
    // motion along the plane's normal (at most the sum of |n_k| times the motion along each axis) is less than its
    // nearer end's distance to the plane: the gaps are lowered until that sum is (one axis, or all in proportion,
    // whichever lasts the most steps). Such a triangle is not hit now either: its exact test finds nothing (the
    // distance is far above the test's tolerance) and is left out.
    if (certified && certify_by_plane(t, a, b, speed, gap)) return true;
    certified = false;
    const double hit = needle_cut::segment_triangle(a, d, length, t);
    if (std::isnan(hit)) return true;
    lowest = std::min(lowest, hit);
    highest = std::max(highest, hit);
    return highest - lowest < needle_cut::kDistinctCrossing;  // two distinct crossings: it passes through, stop
  });
  if (!walked) return true;
  return finish(certified);
}

std::vector<std::int64_t> NeedleBondCut::scan_certified(const Grid& grid, const BondNetwork& bonds, const std::vector<Vec3d>& x) {
  const std::vector<std::uint8_t> side = needle_cut::box_sides(x, grid.lo, grid.hi);
  const std::int32_t now_index = static_cast<std::int32_t>(needle_motion_.size() - 1);
  const Eigen::Vector3d now = needle_motion_.back();
  const Eigen::Vector3d rate = needle_motion_.size() > 1 ? Eigen::Vector3d(now - needle_motion_[needle_motion_.size() - 2]) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d dilation = (kCertificateSteps * rate).cwiseMax(Eigen::Vector3d::Constant(kMinDilationMm));
  std::atomic<std::int64_t> made{0}, skipped{0};
  std::vector<std::int64_t> found_all = parallel_collect_chunks<std::int64_t>(
      static_cast<std::int64_t>(candidates_.size()), [&](std::int64_t begin, std::int64_t end, std::vector<std::int64_t>& found) {
        const Bond* const all = bonds.bonds.data();
        const std::uint8_t* const sides = side.data();
        const Vec3d* const positions = x.data();
        const IntactPair* const pairs = candidates_.data();
        Certificate* const certificates = certificates_.data();
        std::int64_t chunk_made = 0, chunk_skipped = 0;
        for (std::int64_t k = begin; k < end; ++k) {
          const IntactPair pair = pairs[k];
          if (sides[pair.i] & sides[pair.j]) continue;
          if (all[pair.bond].broken) continue;
          const Vec3d& a = positions[pair.i];
          const Vec3d& b = positions[pair.j];
          Certificate& c = certificates[k];
          if (c.gap[0] > 0 && c.gap[1] > 0 && c.gap[2] > 0) {
            const Eigen::Vector3d& then = needle_motion_[static_cast<size_t>(c.motion_index)];
            bool holds = true;
            for (int axis = 0; axis < 3 && holds; ++axis) {
              const double moved = std::max(std::abs(a[axis] - c.a[axis]), std::abs(b[axis] - c.b[axis])) + (now[axis] - then[axis]);
              holds = moved < c.gap[axis];
            }
            if (holds) {
              ++chunk_skipped;
              continue;
            }
          }
          ++chunk_made;
          // A bond whose box overlapped a triangle's at its last test most likely does again: the plain walk first.
          if (c.gap[0] < 0) {
            bool overlapped = false;
            if (passes_through(grid, a, b, overlapped)) {
              found.push_back(pair.bond);
              continue;
            }
            if (overlapped) continue;
          }
          Eigen::Vector3d gap;
          if (passes_through_or_certify(grid, a, b, dilation, rate, gap)) {
            found.push_back(pair.bond);
            continue;
          }
          if (!(gap.array() > 0).all()) {  // no certificate: a box overlapped (or a gap closed to nothing)
            c.gap[0] = c.gap[1] = c.gap[2] = -1;
            continue;
          }
          for (int axis = 0; axis < 3; ++axis) {
            c.a[axis] = a[axis];
            c.b[axis] = b[axis];
            c.gap[axis] = gap[axis];
          }
          c.motion_index = now_index;
        }
        made += chunk_made;
        skipped += chunk_skipped;
      });
  tests_made_ += made;
  tests_skipped_ += skipped;
  return found_all;
}

void NeedleBondCut::track_needle_motion(const Eigen::MatrixX3d& needle_x, std::uint64_t mirrored_signature) {
  const bool same_needle = last_needle_x_.rows() == needle_x.rows() && !needle_motion_.empty();
  if (same_needle) needle_motion_.push_back(needle_motion_.back() + (needle_x - last_needle_x_).cwiseAbs().colwise().maxCoeff().transpose());
  else needle_motion_.assign(1, Eigen::Vector3d::Zero());
  last_needle_x_ = needle_x;
  if (!same_needle || mirrored_signature != mirrored_signature_)
    for (Certificate& c : certificates_) c.gap[0] = c.gap[1] = c.gap[2] = 0;  // none, and no overlap known
  mirrored_signature_ = mirrored_signature;
}

}  // namespace needle
