#pragma once
// The needle a simulation or analysis works on: a tip (recipe, preset, d_a, or a plain flat-ended
// rod for checks), cut to a length behind A, meshed with gmsh. Shared by `needle stiffness` and
// `needle simulate`.
#include <string>
#include <vector>

#include "geometry/tip_geometry.h"
#include "mesher/needle_mesher.h"
#include "mesher/tet_mesh.h"

namespace needle {

struct NeedleBuild {
  TipGeometry tip;
  TetMesh mesh;
  std::vector<std::string> tip_facets;  // boundary tags of the tip's ground facets (the load faces)
  double mesh_seconds = 0;
};

// Meshes the tip (full, or the z >= 0 half) for the solver, without gmsh's high-order optimiser.
NeedleBuild build_needle(const TipGeometry& tip, bool half_model, const NeedleMeshOptions& mesh_options);

}  // namespace needle
