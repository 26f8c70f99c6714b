#pragma once
// Reproducing-kernel (RK) shape functions with a linear basis and the cubic B-spline kernel
// (Liu, Jun & Zhang 1995; Chen et al. 1996): for a point x covered by the supports of centres j,
//   Psi_j(x) = H(0)^T M(x)^-1 H(x - X_j) phi(|x - X_j| / a_j),   H(d) = [1, d_x, d_y, d_z] / scale,
// (phi(|(x - X_j) ./ a_j|) for ellipsoidal supports, kernel_supports.h)
//   M(x)     = sum_j H(x - X_j) H(x - X_j)^T phi_j,
// so that sum_j Psi_j = 1 and sum_j Psi_j X_j = x exactly (linear reproduction). Gradients are the
// full derivatives (including dM/dx), so sum_j grad Psi_j = 0 and sum_j X_j (x) grad Psi_j = I exactly.
//
// Evaluated at the particles themselves (direct nodal integration) and stored as compressed rows:
// row i holds, for every centre j covering particle i, Psi_j(X_i) and grad Psi_j(X_i). An entry can be
// cut (a broken bond): it then leaves the row and the row is rebuilt without it, so separated material
// really stops interacting. A row whose moment matrix is singular (fewer than four non-coplanar
// centres left) is marked invalid: that particle stops being an integration point.
#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <vector>

#include "solver/tissue/kernel_supports.h"
#include "solver/tissue/neighbour_search.h"

namespace needle {

using Vec3 = std::array<double, 3>;

struct RkShapeFunctions {
  // Rows: evaluation points; entries: covering centres (sorted by index).
  std::vector<std::int64_t> offset;  // #rows + 1
  std::vector<std::int32_t> centre;  // #entries
  std::vector<double> psi;           // #entries  Psi_j(x_i)
  std::vector<Vec3> grad;            // #entries  grad Psi_j(x_i), 1/mm
  std::vector<std::uint8_t> cut;     // #entries  1: entry removed (its psi and grad are 0)
  std::vector<std::uint8_t> valid;   // #rows     0: moment matrix singular, row is all zero
  // Transpose (filled by build_rk_shape_functions): for centre j, the entries naming it.
  std::vector<std::int64_t> column_offset;  // #centres + 1
  std::vector<std::int64_t> column_entry;   // entry ids, ordered by row
  std::vector<std::int32_t> column_row;     // row of each of those entries
  // The entries' values again in column order, {psi, grad}, kept equal to psi and grad by every writer
  // (set_rk_entry): a gather over a column then reads memory in order instead of one entry per cache line.
  std::vector<std::array<double, 4>> column_value;
  std::vector<std::int64_t> entry_slot;     // #entries: each entry's place in the column arrays

  std::int64_t rows() const { return static_cast<std::int64_t>(offset.size()) - 1; }
  std::int64_t entries() const { return static_cast<std::int64_t>(centre.size()); }
};

// Sets entry e's psi and grad, and their copy in the transpose if there is one.
inline void set_rk_entry(RkShapeFunctions& rk, std::int64_t e, double psi, const Vec3& grad) {
  const size_t s = static_cast<size_t>(e);
  rk.psi[s] = psi;
  rk.grad[s] = grad;
  if (!rk.entry_slot.empty()) rk.column_value[static_cast<size_t>(rk.entry_slot[s])] = {psi, grad[0], grad[1], grad[2]};
}

// Shape functions of the centres evaluated at the centres themselves (rows = particles), with the
// transpose. centres: #P by 3 (mm), supports: #P (spheres of dilation x spacing, or ellipsoids).
RkShapeFunctions build_rk_shape_functions(const Eigen::MatrixX3d& centres, const KernelSupports& supports);
// The same over given neighbour lists (row i: the centres allowed to cover particle i).
RkShapeFunctions build_rk_shape_functions(const NeighbourLists& lists, const Eigen::MatrixX3d& centres,
                                          const KernelSupports& supports);

// Shape functions of the centres evaluated at arbitrary points (no transpose), e.g. between particles.
RkShapeFunctions evaluate_rk_shape_functions(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& centres,
                                             const KernelSupports& supports);

// Re-evaluates the given rows (points = the rows' evaluation points) without their cut entries.
void rebuild_rk_rows(RkShapeFunctions& rk, const std::vector<std::int64_t>& rows, const Eigen::MatrixX3d& points,
                     const Eigen::MatrixX3d& centres, const KernelSupports& supports);

}  // namespace needle
