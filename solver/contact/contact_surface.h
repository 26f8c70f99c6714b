#pragma once
// The needle's surface as the tissue contact sees it.
//
//  - Triangles: the mesh's boundary faces except the `symmetry` plane, as linear triangles on the FE
//    nodes (a 6-node face is split into its four corner/mid-edge triangles), each with its facet tag.
//    Forces found on a triangle go to its three nodes by barycentric weights.
//  - A signed-distance level set (OpenVDB) of the closed reference surface (a half model is closed by
//    its mirror image, so points on the symmetry plane inside the needle are pushed toward the real
//    surface, not through the plane). Its interior band covers the whole cross-section, so a point
//    deep inside still gets a distance and a normal.
//  - A uniform grid of the reference triangles, to find the triangle under a reference point.
//
// The level set lives in the reference configuration; a current point p is pulled back through the
// current triangle closest to it (pull_back), exact for the linear triangles up to their own rotation.
#include <Eigen/Dense>
#include <optional>
#include <string>
#include <vector>

#include "mesher/needle_level_set.h"
#include "mesher/tet_mesh.h"

namespace needle {

struct ContactSurfaceOptions {
  double voxel_mm = 0.02;  // level-set resolution (distance error about half a voxel)
};

// Where a reference point lands on the surface.
struct SurfacePoint {
  int triangle = -1;
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();  // barycentric, on the triangle's nodes
  double distance_mm = 0;                             // from the query point to the triangle
};

class ContactSurface {
 public:
  // InputError if the mesh's surface (closed by its mirror image for a half model) is not closed.
  ContactSurface(const TetMesh& mesh, const ContactSurfaceOptions& options = {});

  int num_triangles() const { return static_cast<int>(triangles_.rows()); }
  const Eigen::MatrixX3i& triangles() const { return triangles_; }  // FE node indices
  int triangle_tag(int t) const { return tag_[t]; }                  // index into tag_names()
  const std::vector<std::string>& tag_names() const { return tag_names_; }
  const std::vector<int>& nodes() const { return nodes_; }  // FE nodes on the contact surface
  const Eigen::MatrixX3d& reference_positions() const { return reference_; }  // all FE nodes, mm
  bool half_model() const { return half_model_; }
  // The box of the surface nodes at x (rows: all FE nodes), widened to the mirror image a half model's surface is
  // closed with (z from -max z): where the contact can push a particle from.
  void closed_bounds(const Eigen::MatrixX3d& x, Eigen::Vector3d& lo, Eigen::Vector3d& hi) const;
  const NeedleLevelSet& level_set() const { return *level_set_; }
  // Radius of the largest ball around any interior point free of surface nodes: the search radius
  // for the pull-back node.
  double node_search_radius_mm() const { return node_search_radius_mm_; }

  // The triangle nearest a reference point, searched within one grid cell (about the mesh size);
  // triangle -1 if there is none that close.
  SurfacePoint locate(const Eigen::Vector3d& reference_point) const;

  // A current point p pulled back to the reference configuration: the closest point on the current
  // triangles around the surface node nearest p (its one ring), carried to the reference triangle by its
  // barycentric weights, plus the offset p - closest point turned with that triangle. Continuous where
  // the nearest node changes (unlike X = p - u_node, whose jump is the local rotation times a node
  // spacing: 0.07 mm in a bent 0.4 mm mesh, more than the contact's skin).
  Eigen::Vector3d pull_back(const Eigen::Vector3d& p, int near_node, const Eigen::MatrixX3d& current) const;

 private:
  Eigen::MatrixX3i triangles_;
  std::vector<int> tag_;
  std::vector<std::string> tag_names_;
  std::vector<int> nodes_;
  Eigen::MatrixX3d reference_;  // the mesh's node positions
  bool half_model_ = false;
  std::optional<NeedleLevelSet> level_set_;
  double node_search_radius_mm_ = 0;
  // Triangle grid (reference configuration): CSR over cells.
  Eigen::Vector3d grid_origin_;
  Eigen::Vector3i grid_cells_;
  double grid_cell_mm_ = 0;
  std::vector<int> cell_start_, cell_triangles_;
  std::vector<int> node_triangle_start_, node_triangles_;  // node -> incident triangles (CSR)
};

}  // namespace needle
