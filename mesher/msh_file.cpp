#include "mesher/msh_file.h"

#include <gmsh.h>

#include <filesystem>
#include <fmt/format.h>
#include <map>

#include "core/input_error.h"
#include "geometry/mesh_io.h"
#include "mesher/gmsh_model_mesh.h"
#include "mesher/gmsh_session.h"

namespace needle {

void write_msh(const TetMesh& mesh, const std::string& path) {
  namespace fs = std::filesystem;
  NEEDLE_REQUIRE(fs::path(path).extension() == ".msh", fmt::format("'{}': a gmsh mesh file must end in .msh", path));
  write_file_atomically(path, [&](const std::string& scratch_path) {
    detail::GmshSession session("needle");
    detail::gmsh_call("writing " + path, [&] {
      detail::load_tet_mesh(mesh);
      gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
      gmsh::option::setNumber("Mesh.Binary", 0);
      gmsh::write(scratch_path);
    });
  });
}

TetMesh read_msh(const std::string& path) {
  NEEDLE_REQUIRE(std::filesystem::is_regular_file(path), fmt::format("'{}' does not exist", path));
  detail::GmshSession session("read");
  TetMesh mesh;
  try {
    detail::gmsh_call("reading " + path, [&] {
      gmsh::open(path);
      std::vector<int> types;
      gmsh::model::mesh::getElementTypes(types, 3);
      int order = 0;
      for (int t : types) {
        const int o = t == 4 ? 1 : t == 11 ? 2 : 0;
        NEEDLE_REQUIRE(o != 0, fmt::format("'{}' holds volume elements other than 4- or 10-node tetrahedra", path));
        NEEDLE_REQUIRE(order == 0 || order == o, fmt::format("'{}' mixes 4- and 10-node tetrahedra", path));
        order = o;
      }
      NEEDLE_REQUIRE(order != 0, fmt::format("'{}' holds no tetrahedra", path));
      gmsh::vectorpair groups;
      gmsh::model::getPhysicalGroups(groups, 2);
      std::vector<std::string> names;
      std::map<int, int> surface_tag;
      for (const auto& [dim, group] : groups) {
        std::string name;
        gmsh::model::getPhysicalName(2, group, name);
        if (name.empty()) name = fmt::format("surface_{}", group);
        names.push_back(name);
        std::vector<int> entities;
        gmsh::model::getEntitiesForPhysicalGroup(2, group, entities);
        for (int e : entities) surface_tag[e] = static_cast<int>(names.size()) - 1;
      }
      mesh = detail::extract_tet_mesh(order, surface_tag, names);
    });
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const InputError*>(&e)) throw;
    throw InputError(e.what());
  }
  return mesh;
}

}  // namespace needle
