#include "runs/needle_build.h"

#include <chrono>
#include <fmt/format.h>

#include "core/input_error.h"

namespace needle {

NeedleBuild build_needle(const TipGeometry& tip, bool half_model, const NeedleMeshOptions& mesh_options) {
  NeedleBuild b;
  b.tip = tip;
  const auto start = std::chrono::steady_clock::now();
  // gmsh's high-order optimiser is slow on coarse curved shafts (7.5 s on a 3 k-tet rod, still leaving
  // folded tets); the mesher straightens the few tets it would fix instead (mesh_quality.h).
  NeedleMeshOptions options = mesh_options;
  options.high_order_optimize = false;
  b.mesh = mesh_needle(tip, half_model, options);
  b.mesh_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const FacetPlane& f : tip.facets)
    if (b.mesh.tag_index(f.name) >= 0) b.tip_facets.push_back(f.name);
  return b;
}

}  // namespace needle
