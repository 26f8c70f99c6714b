#include "geometry/section_properties.h"

#include <array>
#include <cmath>

namespace needle {

void SectionIntegrals::add_segment(double y1, double z1, double y2, double z2) {
  const double cross = y1 * z2 - y2 * z1;
  area_ += 0.5 * cross;
  first_y_ += (y1 + y2) * cross / 6.0;
  first_z_ += (z1 + z2) * cross / 6.0;
  second_yy_ += (y1 * y1 + y1 * y2 + y2 * y2) * cross / 12.0;
  second_zz_ += (z1 * z1 + z1 * z2 + z2 * z2) * cross / 12.0;
}

SectionProperties SectionIntegrals::finish(double x_mm) const {
  SectionProperties s;
  s.x_mm = x_mm;
  s.area_mm2 = area_;
  if (area_ > 0.0) {
    s.centroid_y_mm = first_y_ / area_;
    s.centroid_z_mm = first_z_ / area_;
    s.I_z_mm4 = second_yy_ - area_ * s.centroid_y_mm * s.centroid_y_mm;
    s.I_y_mm4 = second_zz_ - area_ * s.centroid_z_mm * s.centroid_z_mm;
  }
  return s;
}

std::vector<SectionProperties> surface_sections(const TriSurface& surface, const std::vector<double>& x_mm) {
  std::vector<SectionProperties> sections;
  sections.reserve(x_mm.size());
  for (double x0 : x_mm) {
    SectionIntegrals integrals;
    for (int f = 0; f < surface.num_faces(); ++f) {
      std::array<Eigen::Vector3d, 3> p;
      std::array<double, 3> s;
      for (int k = 0; k < 3; ++k) {
        p[k] = surface.V.row(surface.F(f, k)).transpose();
        s[k] = p[k].x() - x0;
      }
      // Points where the triangle's edges cross the plane (vertices exactly on it count once).
      std::array<Eigen::Vector3d, 2> cut;
      int count = 0;
      for (int k = 0; k < 3 && count < 2; ++k) {
        const int k2 = (k + 1) % 3;
        const bool a_neg = s[k] < 0, b_neg = s[k2] < 0;
        if (a_neg != b_neg) {
          const double t = s[k] / (s[k] - s[k2]);
          cut[count++] = p[k] + t * (p[k2] - p[k]);
        }
      }
      if (count != 2) continue;
      const Eigen::Vector3d normal = (p[1] - p[0]).cross(p[2] - p[0]);
      // In-plane outward direction (n_y, n_z); counter-clockwise tangent is (-n_z, n_y).
      const Eigen::Vector2d tangent(-normal.z(), normal.y());
      Eigen::Vector2d a(cut[0].y(), cut[0].z()), b(cut[1].y(), cut[1].z());
      if (tangent.dot(b - a) < 0) std::swap(a, b);
      integrals.add_segment(a.x(), a.y(), b.x(), b.y());
    }
    sections.push_back(integrals.finish(x0));
  }
  return sections;
}

}  // namespace needle
