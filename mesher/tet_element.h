#pragma once
// Shape functions, quadrature and lumped masses of the 4-node (linear) and 10-node (quadratic)
// tetrahedra in the node order of tet_mesh.h (VTK). Reference coordinates xi = (L1, L2, L3) with
// barycentric L0 = 1 - L1 - L2 - L3; corner k sits where L_k = 1.
//   T4:  N_k = L_k.
//   T10: corner N_k = L_k (2 L_k - 1); edge (i, j) N = 4 L_i L_j.
#include <Eigen/Dense>
#include <vector>

namespace needle {

struct TetQuadraturePoint {
  Eigen::Vector3d xi;
  double weight;  // weights sum to 1/6, the reference tet's volume
};

// The rule used for an element of this order: 1 point (T4, exact for constants: the T4 strain is
// constant) or 4 points (T10, exact for quadratics: the straight T10's stiffness integrand).
const std::vector<TetQuadraturePoint>& tet_quadrature(int order);

// Shape functions at xi (nodes_per_tet values) and their derivatives d N / d xi (nodes_per_tet x 3).
Eigen::VectorXd tet_shape_values(int order, const Eigen::Vector3d& xi);
Eigen::MatrixXd tet_shape_gradients(int order, const Eigen::Vector3d& xi);

// Fraction of an element's mass each node receives in the lumped (diagonal) mass matrix.
// T4: row sums, 1/4 each. T10: row sums would give the corners negative mass (-1/20), so the
// diagonal of the consistent mass matrix is scaled to the element mass (Hinton-Rock-Zienkiewicz):
// corners 6/216 = 1/36, edges 32/216 = 4/27 (from the consistent diagonal V/70 and 8V/105).
const std::vector<double>& tet_lumped_mass_fractions(int order);

}  // namespace needle
