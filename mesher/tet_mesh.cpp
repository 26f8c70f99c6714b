#include "mesher/tet_mesh.h"

#include <algorithm>
#include <map>
#include <set>
#include <stdexcept>

#include "core/input_error.h"

namespace needle {

int TetMesh::tag_index(const std::string& name) const {
  for (size_t i = 0; i < tag_names.size(); ++i)
    if (tag_names[i] == name) return static_cast<int>(i);
  return -1;
}

double signed_tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

namespace {

using FaceKey = std::array<int, 3>;

FaceKey sorted_key(int a, int b, int c) {
  FaceKey k{a, b, c};
  std::sort(k.begin(), k.end());
  return k;
}

// Swapping corners 1 and 2 reverses orientation; in VTK order the edge nodes follow as
// (0,1)<->(0,2): 4<->6, (1,2) stays 5, (1,3)<->(2,3): 8<->9, (0,3) stays 7.
void flip_tet(Eigen::MatrixXi& T, int t, int order) {
  std::swap(T(t, 1), T(t, 2));
  if (order == 2) {
    std::swap(T(t, 4), T(t, 6));
    std::swap(T(t, 8), T(t, 9));
  }
}

// Reversing a triangle (swap corners 1 and 2): edge nodes (0,1)<->(2,0): 3<->5, (1,2) stays.
void flip_face(Eigen::MatrixXi& F, int f, int order) {
  std::swap(F(f, 1), F(f, 2));
  if (order == 2) std::swap(F(f, 3), F(f, 5));
}

}  // namespace

void orient_tet_mesh(TetMesh& mesh) {
  auto corner = [&](int node) -> Eigen::Vector3d { return mesh.X.row(node).transpose(); };
  std::map<FaceKey, int> opposite_corner;  // face -> the tet corner not on it
  for (int t = 0; t < mesh.num_tets(); ++t) {
    if (signed_tet_volume(corner(mesh.T(t, 0)), corner(mesh.T(t, 1)), corner(mesh.T(t, 2)), corner(mesh.T(t, 3))) < 0)
      flip_tet(mesh.T, t, mesh.order);
    for (int skip = 0; skip < 4; ++skip) {
      int f[3], n = 0;
      for (int c = 0; c < 4; ++c)
        if (c != skip) f[n++] = mesh.T(t, c);
      opposite_corner[sorted_key(f[0], f[1], f[2])] = mesh.T(t, skip);
    }
  }
  for (int b = 0; b < mesh.num_boundary_faces(); ++b) {
    const auto it = opposite_corner.find(sorted_key(mesh.boundary_faces(b, 0), mesh.boundary_faces(b, 1), mesh.boundary_faces(b, 2)));
    if (it == opposite_corner.end()) {
      int missing = 0;
      for (int c = b; c < mesh.num_boundary_faces(); ++c)
        missing += opposite_corner.count(sorted_key(mesh.boundary_faces(c, 0), mesh.boundary_faces(c, 1), mesh.boundary_faces(c, 2))) == 0;
      throw std::runtime_error("mesh: " + std::to_string(missing) + " of " + std::to_string(mesh.num_boundary_faces()) +
                               " boundary triangles are not faces of any tetrahedron (first tag " +
                               std::to_string(mesh.boundary_tag(b)) + ", " + std::to_string(mesh.num_tets()) + " tets)");
    }
    const double v = signed_tet_volume(corner(mesh.boundary_faces(b, 0)), corner(mesh.boundary_faces(b, 1)),
                                       corner(mesh.boundary_faces(b, 2)), corner(it->second));
    if (v > 0) flip_face(mesh.boundary_faces, b, mesh.order);  // the inner corner must lie behind the face
  }
}

void drop_unused_nodes(TetMesh& mesh) {
  std::vector<int> new_index(mesh.num_nodes(), -1);
  int used = 0;
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int c = 0; c < mesh.T.cols(); ++c)
      if (new_index[mesh.T(t, c)] < 0) new_index[mesh.T(t, c)] = used++;
  Eigen::MatrixX3d X(used, 3);
  for (int i = 0; i < mesh.num_nodes(); ++i)
    if (new_index[i] >= 0) X.row(new_index[i]) = mesh.X.row(i);
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int c = 0; c < mesh.T.cols(); ++c) mesh.T(t, c) = new_index[mesh.T(t, c)];
  for (int b = 0; b < mesh.num_boundary_faces(); ++b)
    for (int c = 0; c < mesh.boundary_faces.cols(); ++c) {
      const int n = new_index[mesh.boundary_faces(b, c)];
      if (n < 0) throw std::runtime_error("mesh: a boundary triangle uses a node no tetrahedron has");
      mesh.boundary_faces(b, c) = n;
    }
  mesh.X = std::move(X);
}

TetMesh mirrored_union(const TetMesh& half, int axis) {
  NEEDLE_REQUIRE(axis >= 0 && axis < 3, "mirror axis must be 0, 1 or 2");
  const double scale = std::max(1.0, half.X.cwiseAbs().maxCoeff());
  const double on_plane = 1e-9 * scale;
  const int n = half.num_nodes();
  NEEDLE_REQUIRE(half.X.col(axis).minCoeff() >= -on_plane, "mirrored_union: the half model has nodes on both sides of the plane");
  // Node i of the mirror is i itself on the plane, else a new node.
  std::vector<int> image(static_cast<size_t>(n));
  int count = n;
  for (int i = 0; i < n; ++i) image[static_cast<size_t>(i)] = std::abs(half.X(i, axis)) <= on_plane ? i : count++;
  TetMesh full;
  full.order = half.order;
  full.tag_names = half.tag_names;
  full.X.resize(count, 3);
  full.X.topRows(n) = half.X;
  for (int i = 0; i < n; ++i) {
    if (image[static_cast<size_t>(i)] == i) {
      full.X(i, axis) = 0.0;
      continue;
    }
    full.X.row(image[static_cast<size_t>(i)]) = half.X.row(i);
    full.X(image[static_cast<size_t>(i)], axis) = -half.X(i, axis);
  }
  auto mirrored_cells = [&](const Eigen::MatrixXi& cells) {
    Eigen::MatrixXi m(cells.rows(), cells.cols());
    for (Eigen::Index r = 0; r < cells.rows(); ++r)
      for (Eigen::Index k = 0; k < cells.cols(); ++k) m(r, k) = image[static_cast<size_t>(cells(r, k))];
    return m;
  };
  full.T.resize(2 * half.num_tets(), half.T.cols());
  full.T << half.T, mirrored_cells(half.T);
  const int symmetry = half.tag_index("symmetry");
  std::vector<int> kept;
  for (int f = 0; f < half.num_boundary_faces(); ++f)
    if (half.boundary_tag[f] != symmetry) kept.push_back(f);
  const int nf = static_cast<int>(kept.size());
  full.boundary_faces.resize(2 * nf, half.boundary_faces.cols());
  full.boundary_tag.resize(2 * nf);
  for (int k = 0; k < nf; ++k) {
    full.boundary_faces.row(k) = half.boundary_faces.row(kept[static_cast<size_t>(k)]);
    full.boundary_tag[k] = full.boundary_tag[nf + k] = half.boundary_tag[kept[static_cast<size_t>(k)]];
  }
  full.boundary_faces.bottomRows(nf) = mirrored_cells(full.boundary_faces.topRows(nf));
  orient_tet_mesh(full);  // the mirror images are inside out until re-oriented
  return full;
}

std::vector<int> nodes_with_tag(const TetMesh& mesh, const std::string& tag) {
  const int t = mesh.tag_index(tag);
  NEEDLE_REQUIRE(t >= 0, "the mesh has no '" + tag + "' faces");
  std::set<int> nodes;
  for (int f = 0; f < mesh.num_boundary_faces(); ++f)
    if (mesh.boundary_tag[f] == t)
      for (int k = 0; k < mesh.nodes_per_face(); ++k) nodes.insert(mesh.boundary_faces(f, k));
  return {nodes.begin(), nodes.end()};
}

std::vector<int> boundary_nodes(const TetMesh& mesh) {
  std::set<int> nodes;
  for (int f = 0; f < mesh.num_boundary_faces(); ++f)
    for (int k = 0; k < mesh.nodes_per_face(); ++k) nodes.insert(mesh.boundary_faces(f, k));
  return {nodes.begin(), nodes.end()};
}

int nearest_node(const TetMesh& mesh, const Eigen::Vector3d& p) {
  Eigen::Index best = 0;
  (mesh.X.rowwise() - p.transpose()).rowwise().squaredNorm().minCoeff(&best);
  return static_cast<int>(best);
}

}  // namespace needle
