#include "mesher/tet_element.h"

#include <stdexcept>

#include "mesher/tet_mesh.h"

namespace needle {
namespace {

void check_order(int order) {
  if (order != 1 && order != 2) throw std::invalid_argument("tet element order must be 1 or 2");
}

// Barycentric coordinates and d L_k / d xi.
Eigen::Vector4d barycentric(const Eigen::Vector3d& xi) { return {1.0 - xi.sum(), xi.x(), xi.y(), xi.z()}; }
Eigen::RowVector3d barycentric_gradient(int k) {
  if (k == 0) return {-1.0, -1.0, -1.0};
  Eigen::RowVector3d g = Eigen::RowVector3d::Zero();
  g[k - 1] = 1.0;
  return g;
}

}  // namespace

const std::vector<TetQuadraturePoint>& tet_quadrature(int order) {
  check_order(order);
  static const std::vector<TetQuadraturePoint> one = {{{0.25, 0.25, 0.25}, 1.0 / 6.0}};
  static const std::vector<TetQuadraturePoint> four = [] {
    const double a = 0.5854101966249685, b = 0.1381966011250105;  // (5 +- 3 sqrt 5) / 20
    return std::vector<TetQuadraturePoint>{{{b, b, b}, 1.0 / 24.0}, {{a, b, b}, 1.0 / 24.0},
                                           {{b, a, b}, 1.0 / 24.0}, {{b, b, a}, 1.0 / 24.0}};
  }();
  return order == 1 ? one : four;
}

Eigen::VectorXd tet_shape_values(int order, const Eigen::Vector3d& xi) {
  check_order(order);
  const Eigen::Vector4d L = barycentric(xi);
  if (order == 1) return L;
  Eigen::VectorXd N(10);
  for (int k = 0; k < 4; ++k) N[k] = L[k] * (2.0 * L[k] - 1.0);
  for (int e = 0; e < 6; ++e) N[4 + e] = 4.0 * L[kTet10EdgeCorners[e][0]] * L[kTet10EdgeCorners[e][1]];
  return N;
}

Eigen::MatrixXd tet_shape_gradients(int order, const Eigen::Vector3d& xi) {
  check_order(order);
  const Eigen::Vector4d L = barycentric(xi);
  Eigen::MatrixXd G(order == 1 ? 4 : 10, 3);
  for (int k = 0; k < 4; ++k) G.row(k) = (order == 1 ? 1.0 : 4.0 * L[k] - 1.0) * barycentric_gradient(k);
  if (order == 2)
    for (int e = 0; e < 6; ++e) {
      const int i = kTet10EdgeCorners[e][0], j = kTet10EdgeCorners[e][1];
      G.row(4 + e) = 4.0 * (L[j] * barycentric_gradient(i) + L[i] * barycentric_gradient(j));
    }
  return G;
}

const std::vector<double>& tet_lumped_mass_fractions(int order) {
  check_order(order);
  static const std::vector<double> t4(4, 0.25);
  static const std::vector<double> t10 = {1.0 / 36, 1.0 / 36, 1.0 / 36, 1.0 / 36, 4.0 / 27, 4.0 / 27,
                                          4.0 / 27, 4.0 / 27, 4.0 / 27, 4.0 / 27};
  return order == 1 ? t4 : t10;
}

}  // namespace needle
