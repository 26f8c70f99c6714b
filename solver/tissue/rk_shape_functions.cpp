#include "solver/tissue/rk_shape_functions.h"

#include <cmath>

#include "solver/tissue/cubic_bspline.h"
#include "core/parallel.h"

namespace needle {
namespace {

using Vec4 = Eigen::Vector4d;
using Mat4 = Eigen::Matrix4d;

// A moment matrix this badly conditioned (centres nearly coplanar, e.g. a particle left with few bonds
// along one crack face) gives gradients that are exact but huge; such a row stops integrating.
constexpr double kMinMomentRcond = 1e-6;

// The kernel's weight phi_j and its gradient at the offset d = x - X_j from centre j.
struct KernelWeight {
  double w;
  Eigen::Vector3d dw;
};

KernelWeight kernel_weight(const KernelSupports& supports, std::int32_t j, const Eigen::Vector3d& d) {
  KernelWeight k;
  if (supports.spherical) {
    const double r = d.norm(), a = supports.radius_mm(j, 0);
    k.w = cubic_bspline(r / a);
    const double dw_dr = r > 0 ? cubic_bspline_derivative(r / a) / a : 0.0;
    for (int c = 0; c < 3; ++c) k.dw[c] = r > 0 ? dw_dr * d[c] / r : 0.0;
    return k;
  }
  const Eigen::Vector3d a = supports.radius_mm.row(j).transpose();
  const Eigen::Vector3d q = d.cwiseQuotient(a);  // the offset in the support's own units
  const double z = q.norm();
  k.w = cubic_bspline(z);
  const double dw_dz = z > 0 ? cubic_bspline_derivative(z) / z : 0.0;
  for (int c = 0; c < 3; ++c) k.dw[c] = dw_dz * q[c] / a[c];
  return k;
}

// A length for scaling the linear basis (conditioning only; exactness is unaffected).
double basis_length(const KernelSupports& supports, std::int32_t j) {
  return supports.spherical ? supports.radius_mm(j, 0) : supports.radius_mm.row(j).mean();
}

// Fills psi and grad of row `row` at point x; returns false (and zeros) if the moment matrix is singular.
bool evaluate_row(RkShapeFunctions& rk, std::int64_t row, const Eigen::Vector3d& x, const Eigen::MatrixX3d& centres,
                  const KernelSupports& supports) {
  const std::int64_t begin = rk.offset[static_cast<size_t>(row)], end = rk.offset[static_cast<size_t>(row + 1)];
  double scale = 0;
  int active = 0;
  for (std::int64_t e = begin; e < end; ++e)
    if (!rk.cut[static_cast<size_t>(e)]) {
      scale += basis_length(supports, rk.centre[static_cast<size_t>(e)]);
      ++active;
    }
  auto zero_row = [&] {
    for (std::int64_t e = begin; e < end; ++e) set_rk_entry(rk, e, 0, {0, 0, 0});
    return false;
  };
  if (active < 4) return zero_row();
  scale /= active;  // basis scaled by the mean support radius for conditioning; exactness is unaffected
  const double inv_scale = 1.0 / scale;

  Mat4 M = Mat4::Zero();
  std::array<Mat4, 3> dM{Mat4::Zero(), Mat4::Zero(), Mat4::Zero()};
  for (std::int64_t e = begin; e < end; ++e) {
    if (rk.cut[static_cast<size_t>(e)]) continue;
    const std::int32_t j = rk.centre[static_cast<size_t>(e)];
    const Eigen::Vector3d d = x - centres.row(j).transpose();
    const KernelWeight kw = kernel_weight(supports, j, d);
    const double w = kw.w;
    const Vec4 H(1.0, d.x() * inv_scale, d.y() * inv_scale, d.z() * inv_scale);
    M.noalias() += w * H * H.transpose();
    for (int k = 0; k < 3; ++k) {
      const double dw = kw.dw[k];
      Vec4 dH = Vec4::Zero();
      dH[k + 1] = inv_scale;
      dM[static_cast<size_t>(k)].noalias() += w * (dH * H.transpose() + H * dH.transpose()) + dw * H * H.transpose();
    }
  }
  const Eigen::FullPivLU<Mat4> lu(M);
  if (!lu.isInvertible() || lu.rcond() < kMinMomentRcond) return zero_row();
  const Vec4 b = lu.solve(Vec4::UnitX());
  std::array<Vec4, 3> db;
  for (int k = 0; k < 3; ++k) db[static_cast<size_t>(k)] = -lu.solve(dM[static_cast<size_t>(k)] * b);

  for (std::int64_t e = begin; e < end; ++e) {
    if (rk.cut[static_cast<size_t>(e)]) {
      set_rk_entry(rk, e, 0, {0, 0, 0});
      continue;
    }
    const std::int32_t j = rk.centre[static_cast<size_t>(e)];
    const Eigen::Vector3d d = x - centres.row(j).transpose();
    const KernelWeight kw = kernel_weight(supports, j, d);
    const double w = kw.w;
    const Vec4 H(1.0, d.x() * inv_scale, d.y() * inv_scale, d.z() * inv_scale);
    const double bH = b.dot(H);
    Vec3 g;
    for (int k = 0; k < 3; ++k) {
      const double dw = kw.dw[k];
      g[static_cast<size_t>(k)] = db[static_cast<size_t>(k)].dot(H) * w + b[k + 1] * inv_scale * w + bH * dw;
    }
    set_rk_entry(rk, e, bH * w, g);
  }
  return true;
}

RkShapeFunctions rows_from_lists(const NeighbourLists& lists) {
  RkShapeFunctions rk;
  rk.offset = lists.offset;
  rk.centre = lists.index;
  const size_t n = rk.centre.size();
  rk.psi.assign(n, 0.0);
  rk.grad.assign(n, Vec3{0, 0, 0});
  rk.cut.assign(n, 0);
  rk.valid.assign(static_cast<size_t>(rk.rows()), 0);
  return rk;
}

void evaluate_all_rows(RkShapeFunctions& rk, const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& centres,
                       const KernelSupports& supports) {
  parallel_for(rk.rows(), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i)
      rk.valid[static_cast<size_t>(i)] = evaluate_row(rk, i, points.row(i).transpose(), centres, supports) ? 1 : 0;
  });
}

}  // namespace

RkShapeFunctions evaluate_rk_shape_functions(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& centres,
                                             const KernelSupports& supports) {
  RkShapeFunctions rk = rows_from_lists(find_covering_centres(points, centres, supports));
  evaluate_all_rows(rk, points, centres, supports);
  return rk;
}

RkShapeFunctions build_rk_shape_functions(const Eigen::MatrixX3d& centres, const KernelSupports& supports) {
  return build_rk_shape_functions(find_covering_centres(centres, centres, supports), centres, supports);
}

RkShapeFunctions build_rk_shape_functions(const NeighbourLists& lists, const Eigen::MatrixX3d& centres,
                                          const KernelSupports& supports) {
  RkShapeFunctions rk = rows_from_lists(lists);
  evaluate_all_rows(rk, centres, centres, supports);
  // Transpose by counting sort; entries of a column come out ordered by row.
  const std::int64_t num_centres = centres.rows();
  rk.column_offset.assign(static_cast<size_t>(num_centres + 1), 0);
  for (std::int32_t j : rk.centre) ++rk.column_offset[static_cast<size_t>(j + 1)];
  for (std::int64_t j = 0; j < num_centres; ++j) rk.column_offset[static_cast<size_t>(j + 1)] += rk.column_offset[static_cast<size_t>(j)];
  rk.column_entry.resize(rk.centre.size());
  rk.column_row.resize(rk.centre.size());
  rk.column_value.resize(rk.centre.size());
  rk.entry_slot.resize(rk.centre.size());
  std::vector<std::int64_t> fill(rk.column_offset.begin(), rk.column_offset.end() - 1);
  for (std::int64_t i = 0; i < rk.rows(); ++i)
    for (std::int64_t e = rk.offset[static_cast<size_t>(i)]; e < rk.offset[static_cast<size_t>(i + 1)]; ++e) {
      const std::int64_t slot = fill[static_cast<size_t>(rk.centre[static_cast<size_t>(e)])]++;
      rk.column_entry[static_cast<size_t>(slot)] = e;
      rk.column_row[static_cast<size_t>(slot)] = static_cast<std::int32_t>(i);
      const Vec3& g = rk.grad[static_cast<size_t>(e)];
      rk.column_value[static_cast<size_t>(slot)] = {rk.psi[static_cast<size_t>(e)], g[0], g[1], g[2]};
      rk.entry_slot[static_cast<size_t>(e)] = slot;
    }
  return rk;
}

void rebuild_rk_rows(RkShapeFunctions& rk, const std::vector<std::int64_t>& rows, const Eigen::MatrixX3d& points,
                     const Eigen::MatrixX3d& centres, const KernelSupports& supports) {
  parallel_for(static_cast<std::int64_t>(rows.size()), [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t k = begin; k < end; ++k) {
      const std::int64_t i = rows[static_cast<size_t>(k)];
      rk.valid[static_cast<size_t>(i)] = evaluate_row(rk, i, points.row(i).transpose(), centres, supports) ? 1 : 0;
    }
  });
}

}  // namespace needle
