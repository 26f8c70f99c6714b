#pragma once
// The blank rod as a closed polygonal prism whose long edges lie exactly on the true cylinder.
// Long edges are placed at every angle where two facets meet on the cylinder, where the groove floor
// meets it, and on the symmetry plane, so the ground solid's corners are exact and each curved facet
// edge is an inscribed polygon of the true ellipse.
#include <vector>

#include "geometry/grinding_recipe.h"
#include "geometry/tip_geometry.h"
#include "geometry/tri_surface.h"

namespace needle {

// Angles (radians, increasing in [0, 2 pi)) of the prism's long edges.
std::vector<double> rod_edge_angles(const TipGeometry& tip, const TessellationOptions& options);

// x positions of the vertex rings, from the base to just past the tip (x > 0), including the
// groove walls and every extra stop exactly.
std::vector<double> rod_ring_positions(const TipGeometry& tip, const TessellationOptions& options,
                                       const std::vector<double>& extra_stops = {});

// Closed, outward-oriented prism between the first and last ring (tags unset): side quads split in
// two, end caps fanned around the axis. The half prism keeps the angles in [0, pi] and is closed by
// the symmetry face z = 0.
TriSurface tessellate_rod(const TipGeometry& tip, const std::vector<double>& angles,
                          const std::vector<double>& rings, bool half_model);

// Most proximal x at which any facet plane still cuts the smooth rod (the heel of the tip).
double tip_heel_x_mm(const TipGeometry& tip);

}  // namespace needle
