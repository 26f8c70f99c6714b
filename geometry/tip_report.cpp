#include "geometry/tip_report.h"

#include <cmath>

#include "geometry/exact_measures.h"
#include "geometry/surface_measures.h"

namespace needle {

std::vector<double> default_section_stations(const TipGeometry& tip, double step_mm) {
  double from = tip.groove ? tip.groove->back_x_mm - 1.0 : -5.0;
  from = std::max(from, tip.base_x_mm + 0.5 * step_mm);
  std::vector<double> stations;
  // Offset by a quarter step so no station falls exactly on a groove wall or ring.
  for (double x = -0.25 * step_mm; x > from; x -= step_mm) stations.push_back(x);
  std::reverse(stations.begin(), stations.end());
  return stations;
}

TipReport make_tip_report(const CadSolid& solid, const std::vector<double>& section_x_mm) {
  const TipGeometry& tip = solid.tip;
  const TriSurface& surface = solid.surface;
  TipReport report;
  report.name = tip.name;
  report.half_model = solid.half_model;
  report.tip_point_mm = most_distal_point(surface);
  report.tip_point_exact_mm = tip.tip_point;
  report.d_a_mm = tip.d_a_mm();
  if (tip.groove) {
    GrooveReport g;
    g.face_y_mm = tip.groove->floor_y_mm;
    g.start_mm = tip.tip_point.x() - tip.groove->front_x_mm;
    g.length_mm = tip.groove->front_x_mm - tip.groove->back_x_mm;
    g.remaining_thickness_mm = tip.groove->floor_y_mm + tip.radius_mm;
    report.groove = g;
  }
  const std::vector<double> areas = area_by_tag_mm2(surface);
  ExactOptions exact;
  exact.half_model = solid.half_model;
  std::vector<int> facet_tags;
  for (size_t i = 0; i < tip.facets.size(); ++i) {
    const FacetPlane& plane = tip.facets[i];
    FacetReport facet;
    facet.name = plane.name;
    facet.tilt_deg = plane.tilt_deg;
    facet.rotation_deg = plane.rotation_deg;
    facet.normal = plane.normal;
    facet.point_mm = plane.point;
    const int tag = surface.tag_index(plane.name);
    facet.area_mm2 = tag >= 0 ? areas[tag] : 0.0;
    facet.area_exact_mm2 = exact_facet_area_mm2(tip, static_cast<int>(i), exact);
    report.facets.push_back(facet);
    facet_tags.push_back(tag);
  }
  for (size_t t = 0; t < surface.tag_names.size(); ++t) report.face_areas_mm2.emplace_back(surface.tag_names[t], areas[t]);
  report.tip_length_mm = report.tip_point_mm.x() - min_x_of_tags(surface, facet_tags);
  report.surface_area_mm2 = surface_area_mm2(surface);
  report.volume_mm3 = enclosed_volume_mm3(surface);
  report.volume_exact_mm3 = exact_volume_mm3(tip, exact);
  report.triangles = surface.num_faces();
  report.vertices = surface.num_vertices();
  report.build_seconds = solid.build_seconds;
  report.sections = surface_sections(surface, section_x_mm);
  return report;
}

}  // namespace needle
