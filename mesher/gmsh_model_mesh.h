#pragma once
// Internal to mesher/: moves a mesh between the current gmsh model and a TetMesh.
#include <map>
#include <string>

#include "mesher/tet_mesh.h"

namespace needle::detail {

// Reads the current model's tets (of the given order) and the triangles of every surface entity
// listed in surface_tag (gmsh surface entity -> index into tag_names), renumbers nodes from 0,
// converts gmsh's node order to VTK's and orients everything (orient_tet_mesh).
TetMesh extract_tet_mesh(int order, const std::map<int, int>& surface_tag, const std::vector<std::string>& tag_names);

// Puts a TetMesh into the current (empty) model as discrete entities: one surface per boundary tag,
// named physical groups for every tag and a physical volume "needle".
void load_tet_mesh(const TetMesh& mesh);

}  // namespace needle::detail
