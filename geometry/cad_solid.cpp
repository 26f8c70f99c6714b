// The only translation unit that sees CGAL: keeps the two-core build fast.
#include "geometry/cad_solid.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/clip.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <algorithm>
#include <chrono>
#include <map>
#include <tuple>
#include <cstdlib>
#define NEEDLE_TRACE(...) if (std::getenv("NEEDLE_DEBUG")) fmt::print(stderr, __VA_ARGS__)
#include <fmt/format.h>
#include <stdexcept>

#include "geometry/rod_tessellation.h"
#include "geometry/surface_measures.h"

namespace needle {
namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

Mesh to_cgal(const TriSurface& surface) {
  Mesh mesh;
  std::vector<Mesh::Vertex_index> vertex(surface.num_vertices());
  for (int v = 0; v < surface.num_vertices(); ++v)
    vertex[v] = mesh.add_vertex(Point(surface.V(v, 0), surface.V(v, 1), surface.V(v, 2)));
  for (int f = 0; f < surface.num_faces(); ++f) {
    if (mesh.add_face(vertex[surface.F(f, 0)], vertex[surface.F(f, 1)], vertex[surface.F(f, 2)]) ==
        Mesh::null_face())
      throw std::logic_error("could not add a triangle to the CGAL mesh (non-manifold input)");
  }
  return mesh;
}

TriSurface from_cgal(const Mesh& mesh) {
  TriSurface surface;
  std::vector<int> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), -1);
  surface.V.resize(mesh.number_of_vertices(), 3);
  int next = 0;
  for (Mesh::Vertex_index v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    surface.V.row(next) << CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z());
    index[v] = next++;
  }
  surface.F.resize(mesh.number_of_faces(), 3);
  int f = 0;
  for (Mesh::Face_index face : mesh.faces()) {
    int k = 0;
    for (Mesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(face), mesh)) {
      if (k == 3) throw std::logic_error("boolean output has a non-triangular face");
      surface.F(f, k++) = index[v];
    }
    ++f;
  }
  return surface;
}

// The groove's removal box, reaching well outside the rod above the floor.
Mesh groove_box(const GrooveBox& g, double radius) {
  const double y0 = g.floor_y_mm, y1 = radius * 2.0 + 1.0, z = radius * 2.0 + 1.0;
  TriSurface box;
  box.V.resize(8, 3);
  const double xs[2] = {g.back_x_mm, g.front_x_mm}, ys[2] = {y0, y1}, zs[2] = {-z, z};
  for (int i = 0; i < 8; ++i) box.V.row(i) << xs[i & 1], ys[(i >> 1) & 1], zs[(i >> 2) & 1];
  // vertex index = ix + 2 iy + 4 iz; faces outward
  box.F.resize(12, 3);
  box.F << 0, 4, 6, 0, 6, 2,  // x = back (-x)
      1, 3, 7, 1, 7, 5,       // x = front (+x)
      0, 1, 5, 0, 5, 4,       // y = floor (-y)
      2, 6, 7, 2, 7, 3,       // y = top (+y)
      0, 2, 3, 0, 3, 1,       // z = -z (-z)
      4, 5, 7, 4, 7, 6;       // z = +z (+z)
  return to_cgal(box);
}

void clip_by_plane(Mesh& mesh, const Eigen::Vector3d& normal, const Eigen::Vector3d& point,
                   const std::string& what) {
  // PMP::clip keeps the negative side: normal . p - normal . point < 0 is the material.
  const Kernel::Plane_3 plane(normal.x(), normal.y(), normal.z(), -normal.dot(point));
  if (std::getenv("NEEDLE_DEBUG")) fmt::print(stderr, "clip {} on {} faces\n", what, mesh.number_of_faces());
  PMP::clip(mesh, plane, CGAL::parameters::clip_volume(true));
  if (mesh.number_of_faces() == 0)
    throw std::runtime_error(fmt::format("grinding '{}' removed the whole rod", what));
}

}  // namespace

bool surface_self_intersects(const TriSurface& surface) { return PMP::does_self_intersect(to_cgal(surface)); }

CadSolid build_cad_solid(const GrindingRecipe& recipe, bool half_model) {
  const auto start = std::chrono::steady_clock::now();
  CadSolid solid;
  solid.tip = resolve_tip(recipe);
  solid.half_model = half_model;
  const TipGeometry& tip = solid.tip;

  // Each piece of the rod gets only the booleans that reach it: the facets cut the tip piece, the
  // groove the piece around it, the rest of the shaft none; each boolean then sees a few thousand
  // triangles instead of the whole rod. Pieces meet at rings behind the heel and behind the groove
  // (never inside the groove), where their identical end caps are dropped and the rings welded. The half model is a half
  // prism from the start, closed by the symmetry face, so no boolean cuts along its many edges.
  const std::vector<double> angles = rod_edge_angles(tip, recipe.tessellation);
  std::vector<double> splits;
  const double tip_split = tip_heel_x_mm(tip) - 0.25;
  const bool tip_split_in_groove = tip.groove && tip_split < tip.groove->front_x_mm + 0.1 &&
                                   tip_split > tip.groove->back_x_mm - 0.6;
  if (tip_split > tip.base_x_mm + 0.5 && !tip_split_in_groove) splits.push_back(tip_split);
  if (tip.groove && tip.groove->back_x_mm - 0.5 > tip.base_x_mm + 0.5) splits.push_back(tip.groove->back_x_mm - 0.5);
  std::sort(splits.begin(), splits.end());
  const std::vector<double> rings = rod_ring_positions(tip, recipe.tessellation, splits);
  // Pieces from the tip backwards; piece 0 carries the facets.
  std::vector<TriSurface> pieces;
  auto piece_end = rings.end();
  for (auto split = splits.rbegin(); split != splits.rend(); ++split) {
    const auto at = std::find(rings.begin(), rings.end(), *split);
    pieces.push_back(tessellate_rod(tip, angles, std::vector<double>(at, piece_end), half_model));
    piece_end = at + 1;
  }
  pieces.push_back(tessellate_rod(tip, angles, std::vector<double>(rings.begin(), piece_end), half_model));
  auto on_split = [&](double x) { return std::find(splits.begin(), splits.end(), x) != splits.end(); };
  std::vector<Eigen::Vector3d> vertices;
  std::map<std::tuple<double, double, double>, int> ring_vertex;
  std::vector<Eigen::Vector3i> faces;
  for (size_t k = 0; k < pieces.size(); ++k) {
    Mesh mesh = to_cgal(pieces[k]);
    if (k == 0)
      for (const FacetPlane& facet : tip.facets) clip_by_plane(mesh, facet.normal, facet.point, facet.name);
    const double piece_min_x = pieces[k].V.col(0).minCoeff(), piece_max_x = pieces[k].V.col(0).maxCoeff();
    if (tip.groove && piece_min_x < tip.groove->front_x_mm && piece_max_x > tip.groove->back_x_mm) {
      Mesh box = groove_box(*tip.groove, tip.radius_mm);
      Mesh grooved;
      NEEDLE_TRACE("groove on piece {} with {} faces\n", k, mesh.number_of_faces());
      if (!PMP::corefine_and_compute_difference(mesh, box, grooved))
        throw std::runtime_error("the groove boolean (corefinement difference) failed");
      mesh = std::move(grooved);
    }
    PMP::remove_degenerate_faces(mesh);
    mesh.collect_garbage();
    if (!CGAL::is_closed(mesh)) throw std::runtime_error("the CAD solid is not closed after the booleans");
    // Join the pieces: only vertices on a split ring are shared (by exact position); inside a piece
    // CGAL's connectivity is kept as is, even where two vertices round to the same double.
    const TriSurface part = from_cgal(mesh);
    std::vector<int> global(part.num_vertices());
    for (int v = 0; v < part.num_vertices(); ++v) {
      const Eigen::Vector3d p = part.V.row(v).transpose();
      if (on_split(p.x())) {
        const auto key = std::make_tuple(p.x(), p.y(), p.z());
        const auto found = ring_vertex.find(key);
        if (found != ring_vertex.end()) {
          global[v] = found->second;
          continue;
        }
        ring_vertex.emplace(key, static_cast<int>(vertices.size()));
      }
      global[v] = static_cast<int>(vertices.size());
      vertices.push_back(p);
    }
    for (int f = 0; f < part.num_faces(); ++f) {
      const double x0 = part.V(part.F(f, 0), 0);
      const bool on_split_cap = on_split(x0) && part.V(part.F(f, 1), 0) == x0 && part.V(part.F(f, 2), 0) == x0;
      if (!on_split_cap) faces.emplace_back(global[part.F(f, 0)], global[part.F(f, 1)], global[part.F(f, 2)]);
    }
  }
  // Drop the cap-centre vertices the dropped caps used.
  std::vector<int> used(vertices.size(), -1);
  int count = 0;
  for (const Eigen::Vector3i& face : faces)
    for (int k = 0; k < 3; ++k)
      if (used[face(k)] < 0) used[face(k)] = count++;
  solid.surface.V.resize(count, 3);
  for (size_t v = 0; v < vertices.size(); ++v)
    if (used[v] >= 0) solid.surface.V.row(used[v]) = vertices[v].transpose();
  solid.surface.F.resize(faces.size(), 3);
  for (size_t f = 0; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k) solid.surface.F(f, k) = used[faces[f](k)];
  const TopologyCheck topology = check_topology(solid.surface);
  if (!topology.closed_manifold())
    throw std::runtime_error("the CAD solid is not a closed manifold: " + topology.describe());
  tag_faces(tip, half_model, recipe.tessellation.chord_tolerance_mm, solid.surface);
  solid.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return solid;
}

}  // namespace needle
