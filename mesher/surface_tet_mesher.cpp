// mesh_surface(): tets inside a closed triangle surface that gmsh takes as given (discrete surfaces,
// one per tag), so no reparametrisation can loop on slivers (shared/DEPENDENCIES.md).
#include <gmsh.h>

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <map>
#include <numeric>

#include "core/input_error.h"
#include "geometry/surface_measures.h"
#include "mesher/gmsh_model_mesh.h"
#include "mesher/gmsh_session.h"
#include "mesher/needle_mesher.h"

namespace needle {

TetMesh mesh_surface(const TriSurface& surface, const NeedleMeshOptions& options) {
  const NeedleMeshOptions o = options.resolved();
  const TopologyCheck topology = check_topology(surface);
  NEEDLE_REQUIRE(topology.closed_manifold(), "the surface cannot be meshed: " + topology.describe());
  const double volume = enclosed_volume_mm3(surface);
  NEEDLE_REQUIRE(volume > 0, "the surface cannot be meshed: it encloses no volume (inside out?)");
  const double expected = 1.5 * volume / (o.size_mm * o.size_mm * o.size_mm / 8.485);
  NEEDLE_REQUIRE(expected < 2.0e7, fmt::format("size {} mm would make about {:.3g} tetrahedra; choose a larger size",
                                               o.size_mm, expected));

  detail::GmshSession session("surface", o.threads);
  TetMesh mesh;
  try {
    detail::gmsh_call("meshing the surface", [&] {
      // One discrete surface holding every triangle (gmsh keeps its mesh as given), closed by a geo
      // volume; the tags come back afterwards by matching the unchanged boundary triangles.
      gmsh::model::addDiscreteEntity(2, 1);
      std::vector<std::size_t> node_tags(static_cast<size_t>(surface.num_vertices()));
      std::iota(node_tags.begin(), node_tags.end(), std::size_t{1});
      std::vector<double> coords(3 * node_tags.size());
      for (int v = 0; v < surface.num_vertices(); ++v)
        for (int k = 0; k < 3; ++k) coords[static_cast<size_t>(3 * v + k)] = surface.V(v, k);
      gmsh::model::mesh::addNodes(2, 1, node_tags, coords);
      std::vector<std::size_t> face_tags(static_cast<size_t>(surface.num_faces())), face_nodes;
      std::iota(face_tags.begin(), face_tags.end(), std::size_t{1});
      for (int f = 0; f < surface.num_faces(); ++f)
        for (int c = 0; c < 3; ++c) face_nodes.push_back(static_cast<std::size_t>(surface.F(f, c)) + 1);
      gmsh::model::mesh::addElementsByType(1, 2, face_tags, face_nodes);
      const int loop = gmsh::model::geo::addSurfaceLoop({1});
      gmsh::model::geo::addVolume({loop});
      gmsh::model::geo::synchronize();
      // HXT: gmsh's Delaunay (1) does not refine the interior of a discrete volume toward the size field.
      gmsh::option::setNumber("Mesh.Algorithm3D", 10);
      gmsh::option::setNumber("Mesh.Optimize", o.optimize ? 1 : 0);
      gmsh::option::setNumber("Mesh.MeshSizeMax", o.size_mm);
      gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
      // Without a size field the interior takes the boundary triangles' sizes, however large.
      const int size_field = gmsh::model::mesh::field::add("MathEval");
      gmsh::model::mesh::field::setString(size_field, "F", fmt::format("{:.9g}", o.size_mm));
      gmsh::model::mesh::field::setAsBackgroundMesh(size_field);
      gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
      gmsh::model::mesh::generate(3);
      if (o.order == 2) {
        // No exact geometry behind a discrete surface: mid-edge nodes stay on its flat triangles.
        gmsh::option::setNumber("Mesh.SecondOrderLinear", 1);
        gmsh::model::mesh::setOrder(2);
      }
      std::vector<std::string> names = surface.tag_names;
      if (names.empty()) names = {"surface"};
      mesh = detail::extract_tet_mesh(o.order, {{1, 0}}, names);
    });
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    if (what.find("PLC Error") == std::string::npos) throw;
    throw InputError("the surface cannot be filled with tets: its triangles intersect or nearly touch (" + what +
                     "). Remesh it with well-shaped triangles");
  }
  if (mesh.num_tets() == 0) throw std::runtime_error("mesher: gmsh produced no tetrahedra inside the surface");
  // Node i of the mesh need not be vertex i of the surface: match corner positions, then tags.
  std::map<std::array<double, 3>, int> vertex_at;
  for (int v = 0; v < surface.num_vertices(); ++v) vertex_at[{surface.V(v, 0), surface.V(v, 1), surface.V(v, 2)}] = v;
  std::map<std::array<int, 3>, int> tag_of_face;
  for (int f = 0; f < surface.num_faces(); ++f) {
    std::array<int, 3> key{surface.F(f, 0), surface.F(f, 1), surface.F(f, 2)};
    std::sort(key.begin(), key.end());
    tag_of_face[key] = surface.tag_names.empty() ? 0 : surface.face_tag(f);
  }
  for (int b = 0; b < mesh.num_boundary_faces(); ++b) {
    std::array<int, 3> key{};
    for (int c = 0; c < 3; ++c) {
      const auto it = vertex_at.find({mesh.X(mesh.boundary_faces(b, c), 0), mesh.X(mesh.boundary_faces(b, c), 1),
                                      mesh.X(mesh.boundary_faces(b, c), 2)});
      if (it == vertex_at.end()) throw std::runtime_error("mesher: gmsh moved a boundary node of the surface");
      key[static_cast<size_t>(c)] = it->second;
    }
    std::sort(key.begin(), key.end());
    const auto tag = tag_of_face.find(key);
    if (tag == tag_of_face.end()) throw std::runtime_error("mesher: gmsh changed the boundary triangles of the surface");
    mesh.boundary_tag(b) = tag->second;
  }
  return mesh;
}

}  // namespace needle
