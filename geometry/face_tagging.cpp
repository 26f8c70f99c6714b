#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

#include "geometry/cad_solid.h"

namespace needle {
namespace {

struct TagPlane {
  int tag;
  Eigen::Vector3d normal, point;
};

}  // namespace

void tag_faces(const TipGeometry& tip, bool half_model, double chord_tolerance_mm, TriSurface& surface) {
  surface.tag_names.clear();
  std::vector<TagPlane> planes;
  auto add_tag = [&](const std::string& name) {
    surface.tag_names.push_back(name);
    return static_cast<int>(surface.tag_names.size()) - 1;
  };
  for (const FacetPlane& facet : tip.facets) planes.push_back({add_tag(facet.name), facet.normal, facet.point});
  if (tip.groove) {
    const GrooveBox& g = *tip.groove;
    const int floor = add_tag("groove_floor"), wall = add_tag("groove_wall");
    planes.push_back({floor, {0, 1, 0}, {0, g.floor_y_mm, 0}});
    planes.push_back({wall, {-1, 0, 0}, {g.front_x_mm, 0, 0}});
    planes.push_back({wall, {1, 0, 0}, {g.back_x_mm, 0, 0}});
  }
  const int shaft = add_tag("shaft");
  planes.push_back({add_tag("base"), {-1, 0, 0}, {tip.base_x_mm, 0, 0}});
  if (half_model) planes.push_back({add_tag("symmetry"), {0, 0, -1}, {0, 0, 0}});

  const double plane_tol = 1e-7;
  const double radius_tol = chord_tolerance_mm + 1e-7;
  surface.face_tag.resize(surface.num_faces());
  for (int f = 0; f < surface.num_faces(); ++f) {
    const Eigen::Vector3d p0 = surface.V.row(surface.F(f, 0)).transpose();
    const Eigen::Vector3d p1 = surface.V.row(surface.F(f, 1)).transpose();
    const Eigen::Vector3d p2 = surface.V.row(surface.F(f, 2)).transpose();
    Eigen::Vector3d normal = (p1 - p0).cross(p2 - p0);
    const bool degenerate = normal.norm() < 1e-14;
    if (!degenerate) normal.normalize();
    int tag = -1;
    for (const TagPlane& plane : planes) {
      const double d = std::max({std::abs(plane.normal.dot(p0 - plane.point)),
                                 std::abs(plane.normal.dot(p1 - plane.point)),
                                 std::abs(plane.normal.dot(p2 - plane.point))});
      if (d <= plane_tol && (degenerate || normal.dot(plane.normal) > 0.99)) {
        tag = plane.tag;
        break;
      }
    }
    if (tag < 0) {
      bool on_rod = degenerate || std::abs(normal.x()) < 1e-6;
      for (const Eigen::Vector3d* p : {&p0, &p1, &p2}) {
        const double r = std::hypot(p->y(), p->z());
        on_rod = on_rod && r <= tip.radius_mm + 1e-9 && r >= tip.radius_mm - radius_tol;
      }
      if (on_rod) tag = shaft;
    }
    if (tag < 0) {
      const Eigen::Vector3d c = (p0 + p1 + p2) / 3.0;
      throw std::logic_error(fmt::format(
          "triangle {} at ({:.5f}, {:.5f}, {:.5f}) with normal ({:.3f}, {:.3f}, {:.3f}) lies on no facet",
          f, c.x(), c.y(), c.z(), normal.x(), normal.y(), normal.z()));
    }
    surface.face_tag(f) = tag;
  }
}

}  // namespace needle
