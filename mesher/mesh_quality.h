#pragma once
// Size and quality of a tet mesh, computed from the nodes alone (independent of gmsh's own measures).
#include <string>
#include <vector>

#include "mesher/tet_mesh.h"

namespace needle {

struct MeshQuality {
  int order = 1, nodes = 0, tets = 0, boundary_faces = 0;
  double min_radius_ratio = 0, mean_radius_ratio = 0;  // 3 r_in / r_circ of the corner tet; 1 = regular
  double min_dihedral_deg = 0, max_dihedral_deg = 0;   // of the corner tets
  double min_scaled_jacobian = 0;  // min det J over corners, mid-edges and centroid / det J of the corner tet
  int inverted_tets = 0;           // tets with det J <= 0 at a sample point
  double min_edge_mm = 0, mean_edge_mm = 0, max_edge_mm = 0;  // corner-to-corner edges
  double volume_mm3 = 0;           // exact for straight and curved (T10) tets
  std::vector<double> boundary_area_by_tag_mm2;  // indexed like tag_names
};

MeshQuality measure_quality(const TetMesh& mesh);

// 3 r_in / r_circ of a straight tet (1 for the regular tet, 0 when flat or inverted).
double tet_radius_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d);

// Volume of the (possibly curved) mesh: det J integrated with a rule exact for T10 (degree 3).
double tet_mesh_volume_mm3(const TetMesh& mesh);

// Area of the boundary faces per tag (6-node faces by a degree-5 rule).
std::vector<double> boundary_area_by_tag_mm2(const TetMesh& mesh);

// Makes every T10 tet whose scaled Jacobian is below the threshold straight-sided (its mid-edge nodes
// move to the edge midpoints; neighbours sharing those edges see them straight too), repeating until
// none is left. Curving edges onto the cylinder can fold thin boundary tets; a straight edge costs a
// chord sag of h^2 / 8R on the surface instead. Returns how many tets were straightened.
int straighten_distorted_tets(TetMesh& mesh, double min_scaled_jacobian);

// Position of the point with barycentric coordinates (l0, l1, l2, l3) in tet t (isoparametric).
Eigen::Vector3d tet_point(const TetMesh& mesh, int t, const Eigen::Vector4d& barycentric);

}  // namespace needle
