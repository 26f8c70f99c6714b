#pragma once
// gmsh tetrahedral meshes of a needle, refined where the tip and the groove need it.
//
// Two routes, both ending in the same TetMesh with tagged boundary faces:
//  - mesh_needle(): rebuilds the ideal solid of a TipGeometry in gmsh's OpenCASCADE kernel (exact
//    cylinder, exact planes), so 10-node mid-edge nodes land on the true shaft; the default route.
//  - mesh_surface(): fills any closed triangle surface (the CAD's tagged TriSurface, or a file a user
//    brings) with tets, keeping its triangles as the boundary; mid-edge nodes stay on those triangles.
#include <string>

#include "geometry/tip_geometry.h"
#include "geometry/tri_surface.h"
#include "mesher/tet_mesh.h"

namespace needle {

// Every size is an edge length in mm; each trades accuracy for speed and is a parameter.
struct NeedleMeshOptions {
  int order = 2;                  // 1: T4, 2: T10
  double size_mm = 0.2;           // target size over the tip and the groove (paper: 0.2 mm)
  double tip_size_mm = 0.0;       // near tip point A; 0 means size/2
  double edge_size_mm = 0.0;      // along the sharp facet and groove edges; 0 means size/2
  double shaft_size_mm = 0.0;     // along the shaft away from tip and groove; 0 means 2 x size
  double grading_mm = 1.0;        // distance over which sizes blend from fine to coarse
  int elements_per_circle = 0;    // gmsh curvature sizing on the shaft (0: off)
  int threads = 1;                // 1: gmsh Delaunay, same mesh every run; else HXT on that many threads (0: all)
  bool optimize = true;           // gmsh tet optimisation (and T10 high-order optimisation) after meshing
  bool high_order_optimize = true;  // gmsh's T10 optimiser: better curved tets, but slow on coarse shafts
  double min_scaled_jacobian = 0.02; // T10 tets still below this are straightened (mesh_quality.h)

  // The sizes with defaults filled in; InputError for unphysical values.
  NeedleMeshOptions resolved() const;
};

// Meshes the ideal solid of `tip` (full, or the z >= 0 half with a `symmetry` face).
// Throws InputError for absurd options, std::runtime_error if gmsh fails.
TetMesh mesh_needle(const TipGeometry& tip, bool half_model, const NeedleMeshOptions& options);

// Meshes the solid enclosed by a closed, manifold, outward surface. The surface's triangles become
// the boundary faces and keep their tags; only size_mm, order, threads and optimize apply. Uses gmsh's
// HXT (the only 3D algorithm that refines a discrete volume), so tet counts vary slightly between runs.
// The quality of the result is bounded by the quality of the given triangles: the CAD's own surface,
// with its long shaft triangles, gives slivers (docs/mesher.md), which is why mesh_needle() is the default.
TetMesh mesh_surface(const TriSurface& surface, const NeedleMeshOptions& options);

}  // namespace needle
