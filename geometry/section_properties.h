#pragma once
// Cross-section properties of a solid cut by the plane x = const, for beam checks.
#include <vector>

#include "geometry/tri_surface.h"

namespace needle {

struct SectionProperties {
  double x_mm = 0.0;
  double area_mm2 = 0.0;
  double centroid_y_mm = 0.0;
  double centroid_z_mm = 0.0;
  double I_z_mm4 = 0.0;  // second moment about the z axis through the centroid: bending in the x-y plane
  double I_y_mm4 = 0.0;  // second moment about the y axis through the centroid: bending in the x-z plane
};

// Accumulates the polygon (Green's theorem) integrals of closed boundary segments in the (y, z) plane,
// each oriented counter-clockwise around the material as seen from +x.
class SectionIntegrals {
 public:
  void add_segment(double y1, double z1, double y2, double z2);
  SectionProperties finish(double x_mm) const;

 private:
  double area_ = 0, first_y_ = 0, first_z_ = 0, second_yy_ = 0, second_zz_ = 0;
};

// Sections of a closed, outward-oriented triangle surface at the given x positions.
std::vector<SectionProperties> surface_sections(const TriSurface& surface, const std::vector<double>& x_mm);

}  // namespace needle
