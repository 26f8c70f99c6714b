#include "mesher/needle_mesher.h"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <map>
#include <set>
#include <stdexcept>

#include "core/input_error.h"
#include "mesher/gmsh_model_mesh.h"
#include "mesher/gmsh_session.h"
#include "mesher/mesh_quality.h"

namespace needle {
namespace {

using gmsh::vectorpair;
namespace occ = gmsh::model::occ;

constexpr double kPlaneTol = 1e-6;  // mm, and unit-normal tolerance, for recognising OCC faces

void require_size(double value, const char* name, double max_mm) {
  NEEDLE_REQUIRE(std::isfinite(value) && value > 0,
                 fmt::format("mesh option {} must be a positive length in mm (got {})", name, value));
  NEEDLE_REQUIRE(value >= 0.005, fmt::format("mesh option {} = {} mm is below 0.005 mm: the needle would need "
                                             "billions of tetrahedra", name, value));
  NEEDLE_REQUIRE(value <= max_mm, fmt::format("mesh option {} = {} mm is larger than {} mm: the mesh could not "
                                              "represent the needle", name, value, max_mm));
}

// Estimated tets for a volume at an edge length h (a regular tet has volume h^3 / (6 sqrt 2); a
// Delaunay mesh has about 1.5 times more, smaller ones).
double estimated_tets(double volume_mm3, double h_mm) { return 1.5 * volume_mm3 / (h_mm * h_mm * h_mm / 8.485); }

constexpr double kMaxTets = 2.0e7;

// A planar face gmsh may produce, with the tag it should carry.
struct CandidatePlane {
  std::string tag;
  Eigen::Vector3d normal, point;
};

std::vector<CandidatePlane> candidate_planes(const TipGeometry& tip, bool half_model) {
  std::vector<CandidatePlane> planes;
  for (const FacetPlane& f : tip.facets) planes.push_back({f.name, f.normal, f.point});
  if (tip.groove) {
    planes.push_back({"groove_floor", {0, 1, 0}, {0, tip.groove->floor_y_mm, 0}});
    planes.push_back({"groove_wall", {1, 0, 0}, {tip.groove->front_x_mm, 0, 0}});
    planes.push_back({"groove_wall", {1, 0, 0}, {tip.groove->back_x_mm, 0, 0}});
  }
  planes.push_back({"base", {1, 0, 0}, {tip.base_x_mm, 0, 0}});
  if (half_model) planes.push_back({"symmetry", {0, 0, 1}, {0, 0, 0}});
  return planes;
}

// The tag of one OCC surface after the booleans: the cylinder is the shaft; a plane is matched by
// its normal and a point on it against every plane the recipe can produce.
std::string classify_surface(int surface, const std::vector<CandidatePlane>& planes) {
  std::string type;
  gmsh::model::getType(2, surface, type);
  if (type == "Cylinder") return "shaft";
  if (type != "Plane") throw std::runtime_error(fmt::format("mesher: unexpected OCC surface type '{}'", type));
  std::vector<double> lo, hi, normal;
  gmsh::model::getParametrizationBounds(2, surface, lo, hi);
  const std::vector<double> uv = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])};
  gmsh::model::getNormal(surface, uv, normal);
  std::vector<double> xyz;
  gmsh::model::getValue(2, surface, uv, xyz);
  const Eigen::Vector3d n(normal[0], normal[1], normal[2]), p(xyz[0], xyz[1], xyz[2]);
  for (const CandidatePlane& c : planes)
    if (std::abs(std::abs(n.dot(c.normal)) - 1.0) < kPlaneTol && std::abs(c.normal.dot(p - c.point)) < kPlaneTol)
      return c.tag;
  throw std::runtime_error(fmt::format("mesher: OCC surface {} at ({:.4f}, {:.4f}, {:.4f}) matches no CAD face",
                                       surface, p.x(), p.y(), p.z()));
}

// A half-space n.(p - point) >= 0 cut from the rod, as a large box with one face on the plane.
int half_space_box(const Eigen::Vector3d& normal, const Eigen::Vector3d& point, double extent_mm) {
  const int box = occ::addBox(0, -extent_mm / 2, -extent_mm / 2, extent_mm, extent_mm, extent_mm);
  const Eigen::Vector3d ex(1, 0, 0);
  const Eigen::Vector3d axis = ex.cross(normal);
  const double angle = std::atan2(axis.norm(), ex.dot(normal));
  if (axis.norm() > 1e-12) {
    occ::rotate({{3, box}}, 0, 0, 0, axis.x(), axis.y(), axis.z(), angle);
  } else if (ex.dot(normal) < 0) {
    occ::rotate({{3, box}}, 0, 0, 0, 0, 0, 1, M_PI);
  }
  occ::translate({{3, box}}, point.x(), point.y(), point.z());
  return box;
}

// Builds the ideal solid in OCC and returns its volume tag.
int build_occ_solid(const TipGeometry& tip, bool half_model) {
  const double R = tip.radius_mm;
  const double length = -tip.base_x_mm + R;  // the rod runs past A; the facets remove the rest
  const double extent = 2.0 * (length + 4 * R + 2.0);
  const int rod = occ::addCylinder(tip.base_x_mm, 0, 0, length, 0, 0, R);
  vectorpair tools;
  for (const FacetPlane& f : tip.facets) tools.push_back({3, half_space_box(f.normal, f.point, extent)});
  if (tip.groove) {
    const GrooveBox& g = *tip.groove;
    const double top = R + 1.0;
    tools.push_back({3, occ::addBox(g.back_x_mm, g.floor_y_mm, -top, g.front_x_mm - g.back_x_mm, top - g.floor_y_mm, 2 * top)});
  }
  if (half_model) tools.push_back({3, occ::addBox(tip.base_x_mm - 1, -extent / 2, -extent, extent, extent, extent)});
  vectorpair out;
  std::vector<vectorpair> out_map;
  occ::cut({{3, rod}}, tools, out, out_map);
  occ::synchronize();
  if (out.size() != 1 || out[0].first != 3)
    throw std::runtime_error(fmt::format("mesher: the OCC booleans gave {} pieces instead of one solid", out.size()));
  return out[0].second;
}

// Curves whose edges are sharp in the real needle: boundaries of facet and groove faces, without
// those lying in the symmetry plane or on the base.
std::vector<int> sharp_curves(const std::map<int, std::string>& surface_names, const TipGeometry& tip, bool half_model) {
  vectorpair faces;
  for (const auto& [surface, name] : surface_names)
    if (name != "shaft" && name != "base" && name != "symmetry") faces.push_back({2, surface});
  vectorpair curves;
  gmsh::model::getBoundary(faces, curves, false, false, false);
  std::set<int> result;
  for (const auto& [dim, curve] : curves) {
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(1, std::abs(curve), x0, y0, z0, x1, y1, z1);
    if (half_model && std::abs(z1) < 1e-7) continue;
    if (x1 < tip.base_x_mm + 1e-7) continue;
    result.insert(std::abs(curve));
  }
  return {result.begin(), result.end()};
}

int nearest_point_entity(const Eigen::Vector3d& target) {
  vectorpair points;
  gmsh::model::getEntities(points, 0);
  int best = -1;
  double best_distance = 1e-6;
  for (const auto& [dim, tag] : points) {
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(0, tag, x0, y0, z0, x1, y1, z1);
    const double d = (Eigen::Vector3d(x0, y0, z0) - target).norm();
    if (d < best_distance) best_distance = d, best = tag;
  }
  return best;
}

double longest_curve_mm(const std::vector<int>& curves) {
  double longest = 0;
  for (int c : curves) {
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(1, c, x0, y0, z0, x1, y1, z1);
    longest = std::max(longest, std::hypot(x1 - x0, y1 - y0, z1 - z0));
  }
  return longest;
}

int threshold_field(int distance_field, double size_min, double size_max, double dist_min, double dist_max) {
  namespace field = gmsh::model::mesh::field;
  const int f = field::add("Threshold");
  field::setNumber(f, "InField", distance_field);
  field::setNumber(f, "SizeMin", size_min);
  field::setNumber(f, "SizeMax", size_max);
  field::setNumber(f, "DistMin", dist_min);
  field::setNumber(f, "DistMax", dist_max);
  return f;
}

// Size fields: fine at A and along the sharp edges, `size` over the tip and groove zone, growing to
// the shaft size behind it.
void set_size_fields(const TipGeometry& tip, const NeedleMeshOptions& o, const std::vector<int>& curves, double zone_x_mm) {
  namespace field = gmsh::model::mesh::field;
  std::vector<double> fields;
  if (!curves.empty()) {
    const int distance = field::add("Distance");
    field::setNumbers(distance, "CurvesList", std::vector<double>(curves.begin(), curves.end()));
    const double samples = std::ceil(longest_curve_mm(curves) / (0.5 * o.edge_size_mm));
    field::setNumber(distance, "NNodesByEdge", std::clamp(samples, 20.0, 4000.0));
    fields.push_back(threshold_field(distance, o.edge_size_mm, o.shaft_size_mm, 0.5 * o.edge_size_mm,
                                     0.5 * o.edge_size_mm + o.grading_mm));
  }
  const int a_point = nearest_point_entity(tip.tip_point);
  if (a_point > 0) {
    const int distance = field::add("Distance");
    field::setNumbers(distance, "PointsList", {static_cast<double>(a_point)});
    fields.push_back(threshold_field(distance, o.tip_size_mm, o.shaft_size_mm, o.tip_size_mm, o.tip_size_mm + o.grading_mm));
  }
  const int zone = field::add("MathEval");
  field::setString(zone, "F", fmt::format("min({0:.9g}, {1:.9g} + ({0:.9g} - {1:.9g}) * max(0, {2:.9g} - x) / {3:.9g})",
                                          o.shaft_size_mm, o.size_mm, zone_x_mm, o.grading_mm));
  fields.push_back(zone);
  const int all = field::add("Min");
  field::setNumbers(all, "FieldsList", fields);
  field::setAsBackgroundMesh(all);
}

void set_common_options(const NeedleMeshOptions& o) {
  gmsh::option::setNumber("Mesh.Algorithm", 6);     // Frontal-Delaunay surfaces
  // One thread: gmsh's Delaunay (1), which gives the same mesh on every run. More: HXT (10), parallel
  // but not reproducible from run to run (its tet counts vary by ~0.5 %).
  gmsh::option::setNumber("Mesh.Algorithm3D", o.threads == 1 ? 1 : 10);
  gmsh::option::setNumber("Mesh.Optimize", o.optimize ? 1 : 0);
  // Curving T10 edges onto the cylinder can fold thin boundary tets; gmsh's high-order optimiser (1)
  // moves the interior mid-edge nodes back: min scaled Jacobian 0.02 -> 0.25 on LMB at no cost.
  gmsh::option::setNumber("Mesh.HighOrderOptimize", 0);
}

// Generates the tets, then (order 2) the mid-edge nodes on the true geometry, then tries gmsh's
// high-order optimiser. Curving T10 edges onto the cylinder can fold thin boundary tets; the
// optimiser moves interior mid-edge nodes back (min scaled Jacobian 0.02 -> 0.25 on LMB). When it
// cannot reach its target everywhere it reports an error; the mesh it leaves is still kept, and the
// quality report says how good it is.
void generate(const NeedleMeshOptions& o) {
  gmsh::model::mesh::generate(3);
  if (o.order == 1) return;
  gmsh::model::mesh::setOrder(2);
  if (!o.optimize || !o.high_order_optimize) return;
  try {
    gmsh::model::mesh::optimize("HighOrder");
  } catch (const std::string&) {
  }
}

}  // namespace

NeedleMeshOptions NeedleMeshOptions::resolved() const {
  NEEDLE_REQUIRE(order == 1 || order == 2, fmt::format("mesh order must be 1 (T4) or 2 (T10), got {}", order));
  NeedleMeshOptions o = *this;
  require_size(size_mm, "size_mm", 1.0);
  if (o.tip_size_mm == 0) o.tip_size_mm = 0.5 * size_mm;
  if (o.edge_size_mm == 0) o.edge_size_mm = 0.5 * size_mm;
  if (o.shaft_size_mm == 0) o.shaft_size_mm = 2.0 * size_mm;
  require_size(o.tip_size_mm, "tip_size_mm", 1.0);
  require_size(o.edge_size_mm, "edge_size_mm", 1.0);
  require_size(o.shaft_size_mm, "shaft_size_mm", 2.0);
  NEEDLE_REQUIRE(std::isfinite(grading_mm) && grading_mm > 0, "mesh option grading_mm must be a positive length");
  NEEDLE_REQUIRE(o.shaft_size_mm >= o.size_mm, "mesh option shaft_size_mm must not be smaller than size_mm");
  NEEDLE_REQUIRE(elements_per_circle >= 0 && elements_per_circle <= 360, "elements_per_circle must be in [0, 360]");
  NEEDLE_REQUIRE(threads >= 0, "threads must not be negative");
  NEEDLE_REQUIRE(min_scaled_jacobian >= 0 && min_scaled_jacobian < 1, "min_scaled_jacobian must lie in [0, 1)");
  return o;
}

TetMesh mesh_needle(const TipGeometry& tip, bool half_model, const NeedleMeshOptions& options) {
  const NeedleMeshOptions o = options.resolved();
  const double rod_volume = M_PI * tip.radius_mm * tip.radius_mm * (-tip.base_x_mm) * (half_model ? 0.5 : 1.0);
  const double zone_volume = std::min(rod_volume, M_PI * tip.radius_mm * tip.radius_mm * 30.0);
  const double expected = estimated_tets(zone_volume, o.size_mm) + estimated_tets(rod_volume, o.shaft_size_mm);
  NEEDLE_REQUIRE(expected < kMaxTets, fmt::format("mesh sizes would make about {:.3g} tetrahedra (limit {:.0e}); "
                                                  "choose larger sizes", expected, kMaxTets));
  detail::GmshSession session("needle", o.threads);
  TetMesh mesh;
  detail::gmsh_call("meshing the needle", [&] {
    build_occ_solid(tip, half_model);
    const std::vector<CandidatePlane> planes = candidate_planes(tip, half_model);
    std::vector<std::string> tag_order;
    for (const FacetPlane& f : tip.facets) tag_order.push_back(f.name);
    for (const char* name : {"groove_floor", "groove_wall", "shaft", "base", "symmetry"}) tag_order.push_back(name);

    vectorpair surfaces;
    gmsh::model::getEntities(surfaces, 2);
    std::map<int, std::string> surface_names;
    for (const auto& [dim, s] : surfaces) surface_names[s] = classify_surface(s, planes);
    std::vector<std::string> tag_names;
    for (const std::string& name : tag_order)
      for (const auto& [s, n] : surface_names)
        if (n == name && std::find(tag_names.begin(), tag_names.end(), name) == tag_names.end()) tag_names.push_back(name);
    std::map<int, int> surface_tag;
    for (const auto& [s, n] : surface_names)
      surface_tag[s] = static_cast<int>(std::find(tag_names.begin(), tag_names.end(), n) - tag_names.begin());

    // The fine zone covers the tip and the groove, with a margin of one grading length.
    double zone_x = -4.0 * tip.radius_mm;
    for (const auto& [s, n] : surface_names) {
      if (n == "shaft" || n == "base" || n == "symmetry") continue;
      double x0, y0, z0, x1, y1, z1;
      gmsh::model::getBoundingBox(2, s, x0, y0, z0, x1, y1, z1);
      zone_x = std::min(zone_x, x0);
    }
    zone_x = std::max(zone_x - o.grading_mm, tip.base_x_mm);

    set_size_fields(tip, o, sharp_curves(surface_names, tip, half_model), zone_x);
    set_common_options(o);
    gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
    gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", o.elements_per_circle);
    gmsh::option::setNumber("Mesh.MeshSizeMax", o.shaft_size_mm);
    generate(o);
    mesh = detail::extract_tet_mesh(o.order, surface_tag, tag_names);
  });
  if (mesh.num_tets() == 0) throw std::runtime_error("mesher: gmsh produced no tetrahedra");
  mesh.straightened_tets = straighten_distorted_tets(mesh, o.min_scaled_jacobian);
  return mesh;
}

}  // namespace needle
