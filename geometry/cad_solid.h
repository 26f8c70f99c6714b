#pragma once
// The tessellated CAD solid: the rod prism clipped by every facet plane, the groove subtracted by
// corefinement, optionally cut to the z >= 0 half model, every triangle tagged with its facet.
#include "geometry/grinding_recipe.h"
#include "geometry/tip_geometry.h"
#include "geometry/tri_surface.h"

namespace needle {

struct CadSolid {
  TipGeometry tip;
  TriSurface surface;  // closed, manifold, outward-oriented, tagged
  bool half_model = false;
  double build_seconds = 0.0;
};

// Builds the solid of a recipe. Throws InputError for bad recipes and std::runtime_error if a
// boolean operation fails.
CadSolid build_cad_solid(const GrindingRecipe& recipe, bool half_model = false);

// Whether two of the surface's triangles cross (a closed manifold that intersects itself, e.g. two overlapping
// boxes, encloses no solid its volume measures). The surface must be manifold (check_topology).
bool surface_self_intersects(const TriSurface& surface);

// Tags each triangle with the plane it lies in (facets, groove floor and walls, base, symmetry) or
// `shaft` if it lies on the rod's prism; throws std::logic_error for a triangle that fits none.
void tag_faces(const TipGeometry& tip, bool half_model, double chord_tolerance_mm, TriSurface& surface);

}  // namespace needle
