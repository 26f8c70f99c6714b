#pragma once
// Measures of a triangle surface: areas (total and per tag), enclosed volume, most distal point,
// and the closed/manifold check every imported or exported surface must pass.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "geometry/tri_surface.h"

namespace needle {

struct TopologyCheck {
  int boundary_edges = 0;        // edges with one triangle: the surface is open
  int non_manifold_edges = 0;    // edges with more than two triangles
  int inconsistent_edges = 0;    // edges whose two triangles disagree on orientation
  int degenerate_faces = 0;      // triangles that repeat a vertex
  bool closed_manifold() const {
    return boundary_edges == 0 && non_manifold_edges == 0 && inconsistent_edges == 0 && degenerate_faces == 0;
  }
  std::string describe() const;
};

TopologyCheck check_topology(const TriSurface& surface);
double surface_area_mm2(const TriSurface& surface);
std::vector<double> area_by_tag_mm2(const TriSurface& surface);  // indexed like tag_names
double enclosed_volume_mm3(const TriSurface& surface);           // divergence theorem, outward faces
Eigen::Vector3d most_distal_point(const TriSurface& surface);     // vertex of largest x
double min_x_of_tags(const TriSurface& surface, const std::vector<int>& tags);

// Merges vertices with bit-identical positions (files store one copy per triangle), drops
// unreferenced vertices and triangles whose corners merged.
TriSurface weld_identical_vertices(const TriSurface& surface);

}  // namespace needle
