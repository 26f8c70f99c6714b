#include "apps/needle_build.h"

#include <chrono>
#include <fmt/format.h>

#include "geometry/input_error.h"

namespace needle {

NeedleBuild build_needle(const TipGeometry& tip, bool half_model, const NeedleMeshOptions& mesh_options) {
  NeedleBuild b;
  b.tip = tip;
  const auto start = std::chrono::steady_clock::now();
  b.mesh = mesh_needle(tip, half_model, mesh_options);
  b.mesh_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const FacetPlane& f : tip.facets)
    if (b.mesh.tag_index(f.name) >= 0) b.tip_facets.push_back(f.name);
  return b;
}

}  // namespace needle
