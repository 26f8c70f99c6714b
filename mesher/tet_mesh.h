#pragma once
// A tetrahedral volume mesh with tagged boundary faces: what the mesher hands the solver.
// Node order follows VTK (and therefore ParaView):
//   4-node tet:  corners 0 1 2 3, positively oriented ((x1-x0) x (x2-x0)) . (x3-x0) > 0.
//   10-node tet: corners, then mid-edge nodes of edges (0,1) (1,2) (2,0) (0,3) (1,3) (2,3).
//   3/6-node boundary triangle: corners counter-clockwise seen from outside, then mid-edge nodes
//   of edges (0,1) (1,2) (2,0).
#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

namespace needle {

constexpr std::array<std::array<int, 2>, 6> kTet10EdgeCorners = {{{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}};
constexpr std::array<std::array<int, 2>, 3> kTri6EdgeCorners = {{{0, 1}, {1, 2}, {2, 0}}};

struct TetMesh {
  int order = 1;                       // 1: 4-node tets, 2: 10-node tets
  Eigen::MatrixX3d X;                  // #nodes by 3 positions, mm
  Eigen::MatrixXi T;                   // #tets by 4 (order 1) or 10 (order 2) node indices
  Eigen::MatrixXi boundary_faces;      // #B by 3 or 6 node indices
  Eigen::VectorXi boundary_tag;        // #B index into tag_names
  std::vector<std::string> tag_names;  // CAD face names: top, bottom, ..., shaft, base, symmetry
  int straightened_tets = 0;           // T10 tets the mesher made straight-sided (curving folded them)

  int num_nodes() const { return static_cast<int>(X.rows()); }
  int num_tets() const { return static_cast<int>(T.rows()); }
  int num_boundary_faces() const { return static_cast<int>(boundary_faces.rows()); }
  int nodes_per_tet() const { return order == 2 ? 10 : 4; }
  int nodes_per_face() const { return order == 2 ? 6 : 3; }
  int tag_index(const std::string& name) const;  // -1 if absent
};

}  // namespace needle

namespace needle {

// Signed volume of the straight tet on corners a b c d (positive when d is on the side (b-a)x(c-a) points to).
double signed_tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& d);

// Makes every tet positively oriented (swaps corners 1 and 2 and their edge nodes where needed) and
// every boundary face point away from the tet it bounds. Throws std::runtime_error if a boundary face
// bounds no tet, which would mean the mesh and its boundary disagree.
void orient_tet_mesh(TetMesh& mesh);

// The union of a half model (all nodes on one side of the plane x_axis = 0, its plane faces tagged
// `symmetry`) and its mirror image: a full mesh that is exactly mirror-symmetric, so that anything
// symmetric stays symmetric to round-off in a simulation on it. Nodes on the plane are shared; the
// `symmetry` faces are dropped. InputError if a node lies on the wrong side.
TetMesh mirrored_union(const TetMesh& half, int axis);

// Nodes on the boundary faces with this tag (sorted, unique); InputError if the tag is absent.
std::vector<int> nodes_with_tag(const TetMesh& mesh, const std::string& tag);
// Nodes on any boundary face (sorted, unique).
std::vector<int> boundary_nodes(const TetMesh& mesh);
int nearest_node(const TetMesh& mesh, const Eigen::Vector3d& point_mm);

// Drops nodes no tet uses and renumbers the rest (gmsh keeps geometry points that may be unused).
void drop_unused_nodes(TetMesh& mesh);

}  // namespace needle
