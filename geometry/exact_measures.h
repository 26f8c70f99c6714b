#pragma once
// Measures of the ideal (smooth-cylinder) solid of a TipGeometry, computed independently of the
// triangulated CAD solid: each face or section is a convex region (ellipse or circle clipped by
// half-planes) minus a convex groove part, evaluated on a polygon with many vertices
// (relative error ~ 20 / n^2, 5e-9 at the default n). These are the references the tessellated
// solid is checked against, and the "exact" values reported next to the mesh's.
#include "geometry/section_properties.h"
#include "geometry/tip_geometry.h"

namespace needle {

struct ExactOptions {
  bool half_model = false;   // keep z >= 0 only
  int circle_vertices = 65536;
};

// Area of grinding facet `facet_index` of the ideal solid.
double exact_facet_area_mm2(const TipGeometry& tip, int facet_index, const ExactOptions& options = {});

// Cross-section of the ideal solid at axial position x_mm.
SectionProperties exact_section(const TipGeometry& tip, double x_mm, const ExactOptions& options = {});

// Volume of the ideal solid (sections integrated along x, Simpson's rule between the kinks).
double exact_volume_mm3(const TipGeometry& tip, const ExactOptions& options = {});

}  // namespace needle
