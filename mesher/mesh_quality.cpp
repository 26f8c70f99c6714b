#include "mesher/mesh_quality.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mesher/tet_element.h"

namespace needle {
namespace {

Eigen::Matrix3d jacobian(const TetMesh& mesh, int t, const Eigen::Vector4d& l) {
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();  // columns: d x / d l1, d l2, d l3
  if (mesh.order == 1) {
    for (int k = 0; k < 3; ++k) J.col(k) = (mesh.X.row(mesh.T(t, k + 1)) - mesh.X.row(mesh.T(t, 0))).transpose();
    return J;
  }
  const Eigen::MatrixXd g = tet_shape_gradients(2, l.tail<3>());
  for (int a = 0; a < 10; ++a) J += mesh.X.row(mesh.T(t, a)).transpose() * g.row(a);
  return J;
}

Eigen::Vector3d node(const TetMesh& mesh, int i) { return mesh.X.row(i).transpose(); }

}  // namespace

double tet_radius_ratio(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                        const Eigen::Vector3d& p3) {
  const double volume = signed_tet_volume(p0, p1, p2, p3);
  if (volume <= 0) return 0.0;
  const Eigen::Vector3d a = p1 - p0, b = p2 - p0, c = p3 - p0;
  const double face_area_sum = 0.5 * (a.cross(b).norm() + b.cross(c).norm() + c.cross(a).norm() + (p2 - p1).cross(p3 - p1).norm());
  const double circumradius =
      (a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) + c.squaredNorm() * a.cross(b)).norm() / (12.0 * volume);
  return 3.0 * (3.0 * volume / face_area_sum) / circumradius;
}

Eigen::Vector3d tet_point(const TetMesh& mesh, int t, const Eigen::Vector4d& l) {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  if (mesh.order == 1) {
    for (int a = 0; a < 4; ++a) x += l[a] * node(mesh, mesh.T(t, a));
    return x;
  }
  for (int a = 0; a < 4; ++a) x += l[a] * (2 * l[a] - 1) * node(mesh, mesh.T(t, a));
  for (int e = 0; e < 6; ++e)
    x += 4 * l[kTet10EdgeCorners[e][0]] * l[kTet10EdgeCorners[e][1]] * node(mesh, mesh.T(t, 4 + e));
  return x;
}

double tet_mesh_volume_mm3(const TetMesh& mesh) {
  // Keast's 5-point rule, exact for cubics (det J of a T10 is cubic); weights sum to 1.
  const double a = 0.5, b = 1.0 / 6.0;
  const Eigen::Vector4d points[5] = {{0.25, 0.25, 0.25, 0.25}, {a, b, b, b}, {b, a, b, b}, {b, b, a, b}, {b, b, b, a}};
  const double weights[5] = {-0.8, 0.45, 0.45, 0.45, 0.45};
  double volume = 0;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    if (mesh.order == 1) {
      volume += jacobian(mesh, t, points[0]).determinant() / 6.0;
      continue;
    }
    for (int q = 0; q < 5; ++q) volume += weights[q] * jacobian(mesh, t, points[q]).determinant() / 6.0;
  }
  return volume;
}

std::vector<double> boundary_area_by_tag_mm2(const TetMesh& mesh) {
  // Dunavant's 7-point rule (degree 5) on the reference triangle, weights sum to 1.
  const double a1 = 0.059715871789770, b1 = 0.470142064105115, a2 = 0.797426985353087, b2 = 0.101286507323456;
  const double w0 = 0.225, w1 = 0.132394152788506, w2 = 0.125939180544827;
  const double pts[7][3] = {{1. / 3, 1. / 3, 1. / 3}, {a1, b1, b1}, {b1, a1, b1}, {b1, b1, a1},
                            {a2, b2, b2}, {b2, a2, b2}, {b2, b2, a2}};
  const double w[7] = {w0, w1, w1, w1, w2, w2, w2};
  std::vector<double> area(mesh.tag_names.size(), 0.0);
  for (int f = 0; f < mesh.num_boundary_faces(); ++f) {
    const Eigen::Vector3d p0 = node(mesh, mesh.boundary_faces(f, 0)), p1 = node(mesh, mesh.boundary_faces(f, 1)),
                          p2 = node(mesh, mesh.boundary_faces(f, 2));
    double face_area = 0;
    if (mesh.order == 1) {
      face_area = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    } else {
      const Eigen::Vector3d m01 = node(mesh, mesh.boundary_faces(f, 3)), m12 = node(mesh, mesh.boundary_faces(f, 4)),
                            m20 = node(mesh, mesh.boundary_faces(f, 5));
      for (int q = 0; q < 7; ++q) {
        const double l0 = pts[q][0], l1 = pts[q][1], l2 = pts[q][2];
        // d x / d l1 and d x / d l2 with l0 = 1 - l1 - l2.
        const Eigen::Vector3d du = (1 - 4 * l0) * p0 + (4 * l1 - 1) * p1 + 4 * (l0 - l1) * m01 + 4 * l2 * m12 - 4 * l2 * m20;
        const Eigen::Vector3d dv = (1 - 4 * l0) * p0 + (4 * l2 - 1) * p2 - 4 * l1 * m01 + 4 * l1 * m12 + 4 * (l0 - l2) * m20;
        face_area += 0.5 * w[q] * du.cross(dv).norm();
      }
    }
    area[static_cast<size_t>(mesh.boundary_tag(f))] += face_area;
  }
  return area;
}

namespace {

// det J at corners, mid-edges and centroid over the straight tet's (1 for a straight tet).
double scaled_jacobian(const TetMesh& mesh, int t, const std::vector<Eigen::Vector4d>& samples) {
  const double straight = 6.0 * signed_tet_volume(node(mesh, mesh.T(t, 0)), node(mesh, mesh.T(t, 1)),
                                                  node(mesh, mesh.T(t, 2)), node(mesh, mesh.T(t, 3)));
  if (!(straight > 0)) return -1.0;
  double worst = std::numeric_limits<double>::max();
  for (const Eigen::Vector4d& s : samples) {
    worst = std::min(worst, jacobian(mesh, t, s).determinant() / straight);
    if (mesh.order == 1) break;  // constant over a straight tet
  }
  return worst;
}

std::vector<Eigen::Vector4d> jacobian_samples() {
  std::vector<Eigen::Vector4d> samples;
  for (int a = 0; a < 4; ++a) samples.push_back(Eigen::Vector4d::Unit(a));
  for (const auto& e : kTet10EdgeCorners) samples.push_back(0.5 * (Eigen::Vector4d::Unit(e[0]) + Eigen::Vector4d::Unit(e[1])));
  samples.push_back(Eigen::Vector4d::Constant(0.25));
  return samples;
}

}  // namespace

int straighten_distorted_tets(TetMesh& mesh, double min_scaled_jacobian) {
  if (mesh.order != 2) return 0;
  const std::vector<Eigen::Vector4d> samples = jacobian_samples();
  std::vector<char> done(static_cast<size_t>(mesh.num_tets()), 0);
  int straightened = 0;
  for (int pass = 0; pass < 10; ++pass) {
    int changed = 0;
    for (int t = 0; t < mesh.num_tets(); ++t) {
      if (done[static_cast<size_t>(t)] || scaled_jacobian(mesh, t, samples) >= min_scaled_jacobian) continue;
      for (int e = 0; e < 6; ++e)
        mesh.X.row(mesh.T(t, 4 + e)) =
            0.5 * (mesh.X.row(mesh.T(t, kTet10EdgeCorners[e][0])) + mesh.X.row(mesh.T(t, kTet10EdgeCorners[e][1])));
      done[static_cast<size_t>(t)] = 1;
      ++changed;
    }
    straightened += changed;
    if (changed == 0) break;
  }
  return straightened;
}

MeshQuality measure_quality(const TetMesh& mesh) {
  MeshQuality q;
  q.order = mesh.order;
  q.nodes = mesh.num_nodes();
  q.tets = mesh.num_tets();
  q.boundary_faces = mesh.num_boundary_faces();
  q.min_radius_ratio = q.min_dihedral_deg = q.min_scaled_jacobian = q.min_edge_mm = std::numeric_limits<double>::max();
  double sum_ratio = 0, sum_edge = 0;
  // Sample points for det J: corners, mid-edges, centroid.
  const std::vector<Eigen::Vector4d> samples = jacobian_samples();

  for (int t = 0; t < mesh.num_tets(); ++t) {
    Eigen::Vector3d p[4];
    for (int a = 0; a < 4; ++a) p[a] = node(mesh, mesh.T(t, a));
    const double volume = signed_tet_volume(p[0], p[1], p[2], p[3]);
    // Outward face normals n_k of the face opposite corner k.
    Eigen::Vector3d n[4];
    for (int k = 0; k < 4; ++k) {
      const int i = (k + 1) % 4, j = (k + 2) % 4, l = (k + 3) % 4;
      Eigen::Vector3d c = (p[j] - p[i]).cross(p[l] - p[i]);
      if (c.dot(p[k] - p[i]) > 0) c = -c;
      n[k] = c.normalized();
    }
    const double ratio = tet_radius_ratio(p[0], p[1], p[2], p[3]);
    q.min_radius_ratio = std::min(q.min_radius_ratio, ratio);
    sum_ratio += ratio;
    for (int k = 0; k < 4; ++k)
      for (int l = k + 1; l < 4; ++l) {
        const double dihedral = 180.0 - std::acos(std::clamp(n[k].dot(n[l]), -1.0, 1.0)) * 180.0 / M_PI;
        q.min_dihedral_deg = std::min(q.min_dihedral_deg, dihedral);
        q.max_dihedral_deg = std::max(q.max_dihedral_deg, dihedral);
        const double edge = (p[k] - p[l]).norm();
        q.min_edge_mm = std::min(q.min_edge_mm, edge);
        q.max_edge_mm = std::max(q.max_edge_mm, edge);
        sum_edge += edge;
      }
    const double scaled = scaled_jacobian(mesh, t, samples);  // -1 for an inverted corner tet
    q.min_scaled_jacobian = std::min(q.min_scaled_jacobian, scaled);
    q.inverted_tets += (volume <= 0 || scaled <= 0) ? 1 : 0;
  }
  if (q.tets > 0) {
    q.mean_radius_ratio = sum_ratio / q.tets;
    q.mean_edge_mm = sum_edge / (6.0 * q.tets);
  }
  q.volume_mm3 = tet_mesh_volume_mm3(mesh);
  q.boundary_area_by_tag_mm2 = boundary_area_by_tag_mm2(mesh);
  return q;
}

}  // namespace needle
