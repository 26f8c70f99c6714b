#pragma once
// Every number a designer asks of a ground tip, measured on the tessellated solid, each next to the
// exact value of the smooth solid where one exists.
#include <optional>
#include <string>
#include <vector>

#include "geometry/cad_solid.h"
#include "geometry/section_properties.h"

namespace needle {

struct FacetReport {
  std::string name;
  double tilt_deg = 0, rotation_deg = 0;
  Eigen::Vector3d normal, point_mm;
  double area_mm2 = 0, area_exact_mm2 = 0;
};

struct GrooveReport {
  double face_y_mm = 0, start_mm = 0, length_mm = 0, remaining_thickness_mm = 0;
};

struct TipReport {
  std::string name;
  bool half_model = false;
  Eigen::Vector3d tip_point_mm;        // most distal vertex of the solid
  Eigen::Vector3d tip_point_exact_mm;  // analytic plane intersection
  std::optional<double> d_a_mm;
  std::optional<GrooveReport> groove;
  std::vector<FacetReport> facets;
  std::vector<std::pair<std::string, double>> face_areas_mm2;  // every tag, including groove and shaft
  double tip_length_mm = 0;  // from A back to the most proximal point of any grinding facet (the heel)
  double surface_area_mm2 = 0, volume_mm3 = 0, volume_exact_mm3 = 0;
  int triangles = 0, vertices = 0;
  double build_seconds = 0;
  std::vector<SectionProperties> sections;
};

// Default section stations: every step_mm from just behind the groove (or 5 mm) to the tip.
std::vector<double> default_section_stations(const TipGeometry& tip, double step_mm = 0.5);

TipReport make_tip_report(const CadSolid& solid, const std::vector<double>& section_x_mm);

}  // namespace needle
