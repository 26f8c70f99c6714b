#include "solver/contact/contact_surface.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <map>

#include "core/input_error.h"
#include "geometry/tri_surface.h"
#include "mesher/triangle_distance.h"

namespace needle {
namespace {

// Linear sub-triangles of a 6-node face (corners 0 1 2, mid-edges 3 (01) 4 (12) 5 (20)), all
// counter-clockwise seen from outside like the face.
constexpr int kTri6Split[4][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};

// Barycentric weights of a point c in the plane of triangle abc (c already on the triangle).
Eigen::Vector3d barycentric(const Eigen::Vector3d& c, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& d) {
  const Eigen::Vector3d e0 = b - a, e1 = d - a, w = c - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1), d20 = w.dot(e0), d21 = w.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(std::abs(den) > 0)) return Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3);
  const double v = (d11 * d20 - d01 * d21) / den, s = (d00 * d21 - d01 * d20) / den;
  Eigen::Vector3d out(1 - v - s, v, s);
  out = out.cwiseMax(0.0);
  return out / out.sum();
}

}  // namespace

ContactSurface::ContactSurface(const TetMesh& mesh, const ContactSurfaceOptions& options)
    : tag_names_(mesh.tag_names), reference_(mesh.X) {
  NEEDLE_REQUIRE(std::isfinite(options.voxel_mm) && options.voxel_mm > 0, "contact: the level-set voxel must be positive");
  const int symmetry = mesh.tag_index("symmetry");
  half_model_ = symmetry >= 0;
  std::vector<Eigen::Vector3i> tris;
  for (int f = 0; f < mesh.num_boundary_faces(); ++f) {
    if (mesh.boundary_tag[f] == symmetry) continue;
    if (mesh.order == 2) {
      for (const auto& s : kTri6Split) {
        tris.emplace_back(mesh.boundary_faces(f, s[0]), mesh.boundary_faces(f, s[1]), mesh.boundary_faces(f, s[2]));
        tag_.push_back(mesh.boundary_tag[f]);
      }
    } else {
      tris.emplace_back(mesh.boundary_faces(f, 0), mesh.boundary_faces(f, 1), mesh.boundary_faces(f, 2));
      tag_.push_back(mesh.boundary_tag[f]);
    }
  }
  NEEDLE_REQUIRE(!tris.empty(), "contact: the needle mesh has no boundary faces");
  triangles_.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t) triangles_.row(static_cast<Eigen::Index>(t)) = tris[t].transpose();
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) nodes_.push_back(t[k]);
  std::sort(nodes_.begin(), nodes_.end());
  nodes_.erase(std::unique(nodes_.begin(), nodes_.end()), nodes_.end());
  // Node -> incident triangles (CSR), for the pull-back.
  node_triangle_start_.assign(static_cast<size_t>(mesh.X.rows() + 1), 0);
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) ++node_triangle_start_[static_cast<size_t>(t[k] + 1)];
  for (size_t n = 1; n < node_triangle_start_.size(); ++n) node_triangle_start_[n] += node_triangle_start_[n - 1];
  node_triangles_.resize(static_cast<size_t>(node_triangle_start_.back()));
  {
    std::vector<int> fill(node_triangle_start_.begin(), node_triangle_start_.end() - 1);
    for (size_t t = 0; t < tris.size(); ++t)
      for (int k = 0; k < 3; ++k) node_triangles_[static_cast<size_t>(fill[static_cast<size_t>(tris[t][k])]++)] = static_cast<int>(t);
  }

  // The closed reference surface for the level set: surface nodes, plus for a half model their mirror
  // images (nodes on the plane are their own image) and the mirrored triangles, reversed.
  const Eigen::Vector3d lo = mesh.X.colwise().minCoeff(), hi = mesh.X.colwise().maxCoeff();
  const double plane_tol = 1e-9 * std::max(1.0, (hi - lo).norm());
  std::map<int, int> vertex_of;
  TriSurface closed;
  std::vector<Eigen::Vector3d> vertices;
  for (int n : nodes_) {
    vertex_of[n] = static_cast<int>(vertices.size());
    vertices.push_back(mesh.X.row(n).transpose());
  }
  std::vector<int> mirror_vertex(vertices.size(), -1);
  if (half_model_) {
    for (size_t k = 0; k < nodes_.size(); ++k) {
      const Eigen::Vector3d p = vertices[k];
      if (std::abs(p.z()) <= plane_tol) {
        mirror_vertex[k] = static_cast<int>(k);
        vertices[k].z() = 0.0;
      } else {
        mirror_vertex[k] = static_cast<int>(vertices.size());
        vertices.emplace_back(p.x(), p.y(), -p.z());
      }
    }
  }
  const size_t copies = half_model_ ? 2 : 1;
  closed.V.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (size_t k = 0; k < vertices.size(); ++k) closed.V.row(static_cast<Eigen::Index>(k)) = vertices[k].transpose();
  closed.F.resize(static_cast<Eigen::Index>(copies * tris.size()), 3);
  closed.face_tag.resize(closed.F.rows());
  closed.tag_names = tag_names_;
  for (size_t t = 0; t < tris.size(); ++t) {
    const int a = vertex_of[tris[t][0]], b = vertex_of[tris[t][1]], c = vertex_of[tris[t][2]];
    closed.F.row(static_cast<Eigen::Index>(t)) << a, b, c;
    closed.face_tag[static_cast<Eigen::Index>(t)] = tag_[t];
    if (half_model_) {
      closed.F.row(static_cast<Eigen::Index>(tris.size() + t)) << mirror_vertex[static_cast<size_t>(a)],
          mirror_vertex[static_cast<size_t>(c)], mirror_vertex[static_cast<size_t>(b)];
      closed.face_tag[static_cast<Eigen::Index>(tris.size() + t)] = tag_[t];
    }
  }

  // Search radii: the deepest interior point is at most the half-width of the cross-section from the
  // surface; the nearest surface node is at most one triangle edge further.
  double longest_edge = 0;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) longest_edge = std::max(longest_edge, (mesh.X.row(t[k]) - mesh.X.row(t[(k + 1) % 3])).norm());
  const double half_width = 0.5 * std::max(hi.y() - lo.y(), half_model_ ? 2 * hi.z() : hi.z() - lo.z());
  node_search_radius_mm_ = half_width + longest_edge;
  LevelSetOptions ls;
  ls.voxel_mm = options.voxel_mm;
  ls.half_width_voxels = 3;
  ls.interior_width_voxels = std::min(1000, static_cast<int>(std::ceil(half_width / options.voxel_mm)) + 3);
  try {
    level_set_.emplace(closed, ls);
  } catch (const InputError& e) {
    throw InputError(fmt::format("contact: the needle's surface{} is not closed: {}", half_model_ ? " with its mirror image" : "",
                                 e.what()));
  }

  // Reference triangle grid, cells of about one long edge, each triangle in every cell its box touches.
  grid_cell_mm_ = std::max(longest_edge, 4 * options.voxel_mm);
  const double margin = 0.5 * grid_cell_mm_;
  grid_origin_ = lo.array() - margin - grid_cell_mm_;
  grid_cells_ = (((hi - lo).array() + 2 * margin + 2 * grid_cell_mm_) / grid_cell_mm_).ceil().cast<int>().cwiseMax(1);
  auto cell_of = [&](const Eigen::Vector3d& p) {
    return ((p - grid_origin_) / grid_cell_mm_).array().floor().cast<int>().cwiseMax(0).cwiseMin(grid_cells_.array() - 1).matrix().eval();
  };
  const long num_cells = static_cast<long>(grid_cells_.x()) * grid_cells_.y() * grid_cells_.z();
  std::vector<std::pair<long, int>> entries;
  for (int t = 0; t < num_triangles(); ++t) {
    Eigen::Vector3d tmin = mesh.X.row(triangles_(t, 0)).transpose(), tmax = tmin;
    for (int k = 1; k < 3; ++k) {
      tmin = tmin.cwiseMin(mesh.X.row(triangles_(t, k)).transpose());
      tmax = tmax.cwiseMax(mesh.X.row(triangles_(t, k)).transpose());
    }
    const Eigen::Vector3i c0 = cell_of(tmin.array() - margin), c1 = cell_of(tmax.array() + margin);
    for (int i = c0.x(); i <= c1.x(); ++i)
      for (int j = c0.y(); j <= c1.y(); ++j)
        for (int k = c0.z(); k <= c1.z(); ++k)
          entries.emplace_back((static_cast<long>(i) * grid_cells_.y() + j) * grid_cells_.z() + k, t);
  }
  std::sort(entries.begin(), entries.end());
  cell_start_.assign(static_cast<size_t>(num_cells + 1), 0);
  for (const auto& e : entries) ++cell_start_[static_cast<size_t>(e.first + 1)];
  for (long c = 0; c < num_cells; ++c) cell_start_[static_cast<size_t>(c + 1)] += cell_start_[static_cast<size_t>(c)];
  cell_triangles_.reserve(entries.size());
  for (const auto& e : entries) cell_triangles_.push_back(e.second);
}

void ContactSurface::closed_bounds(const Eigen::MatrixX3d& x, Eigen::Vector3d& lo, Eigen::Vector3d& hi) const {
  lo = hi = x.row(nodes_.front()).transpose();
  for (int n : nodes_) {
    lo = lo.cwiseMin(x.row(n).transpose());
    hi = hi.cwiseMax(x.row(n).transpose());
  }
  if (half_model_) lo.z() = std::min(lo.z(), -hi.z());
}

SurfacePoint ContactSurface::locate(const Eigen::Vector3d& p) const {
  SurfacePoint best;
  const Eigen::Vector3i c = ((p - grid_origin_) / grid_cell_mm_).array().floor().cast<int>();
  if ((c.array() < 0).any() || (c.array() >= grid_cells_.array()).any()) return best;
  const long cell = (static_cast<long>(c.x()) * grid_cells_.y() + c.y()) * grid_cells_.z() + c.z();
  double best_d2 = std::numeric_limits<double>::infinity();
  Eigen::Vector3d best_point = Eigen::Vector3d::Zero();
  for (int k = cell_start_[static_cast<size_t>(cell)]; k < cell_start_[static_cast<size_t>(cell + 1)]; ++k) {
    const int t = cell_triangles_[static_cast<size_t>(k)];
    const Eigen::Vector3d a = reference_.row(triangles_(t, 0)).transpose(), b = reference_.row(triangles_(t, 1)).transpose(),
                          d = reference_.row(triangles_(t, 2)).transpose();
    const Eigen::Vector3d q = closest_point_on_triangle(p, a, b, d);
    const double d2 = (q - p).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best.triangle = t;
      best_point = q;
    }
  }
  if (best.triangle < 0) return best;
  const int t = best.triangle;
  best.weights = barycentric(best_point, reference_.row(triangles_(t, 0)).transpose(), reference_.row(triangles_(t, 1)).transpose(),
                             reference_.row(triangles_(t, 2)).transpose());
  best.distance_mm = std::sqrt(best_d2);
  return best;
}

Eigen::Vector3d ContactSurface::pull_back(const Eigen::Vector3d& p, int near_node, const Eigen::MatrixX3d& x) const {
  const auto corner = [&](const Eigen::MatrixX3d& m, int t, int k) { return m.row(triangles_(t, k)).transpose().eval(); };
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  Eigen::Vector3d best_c = Eigen::Vector3d::Zero();
  for (int e = node_triangle_start_[static_cast<size_t>(near_node)]; e < node_triangle_start_[static_cast<size_t>(near_node) + 1]; ++e) {
    const int t = node_triangles_[static_cast<size_t>(e)];
    const Eigen::Vector3d c = closest_point_on_triangle(p, corner(x, t, 0), corner(x, t, 1), corner(x, t, 2));
    const double d2 = (p - c).squaredNorm();
    if (d2 < best_d2) best_d2 = d2, best = t, best_c = c;
  }
  if (best < 0) return p - (x.row(near_node) - reference_.row(near_node)).transpose();  // a node on no triangle
  const Eigen::Vector3d a = corner(x, best, 0), b = corner(x, best, 1), c = corner(x, best, 2);
  // Barycentric weights of the closest point on the current triangle.
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = best_c - a;
  const double d00 = ab.dot(ab), d01 = ab.dot(ac), d11 = ac.dot(ac), d20 = ap.dot(ab), d21 = ap.dot(ac);
  const double denominator = d00 * d11 - d01 * d01;
  if (!(denominator > 0)) return p - (x.row(near_node) - reference_.row(near_node)).transpose();
  const double v = (d11 * d20 - d01 * d21) / denominator, w = (d00 * d21 - d01 * d20) / denominator;
  const Eigen::Vector3d A = corner(reference_, best, 0), B = corner(reference_, best, 1), C = corner(reference_, best, 2);
  const Eigen::Vector3d on_reference = (1 - v - w) * A + v * B + w * C;
  // The offset from the surface, turned with the triangle.
  const Eigen::Vector3d n_cur = ab.cross(ac).normalized(), n_ref = (B - A).cross(C - A).normalized();
  const Eigen::Vector3d offset = p - best_c;
  if (!n_cur.allFinite() || !n_ref.allFinite()) return on_reference + offset;
  return on_reference + Eigen::Quaterniond::FromTwoVectors(n_cur, n_ref) * offset;
}

}  // namespace needle
