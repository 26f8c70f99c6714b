#pragma once
// gmsh .msh files (ASCII 4.1, gmsh's default), written and read through gmsh itself. The boundary
// tags travel as named physical surfaces; the volume is the physical group "needle".
#include <string>

#include "mesher/tet_mesh.h"

namespace needle {

// Writes the mesh; the file appears complete or not at all.
void write_msh(const TetMesh& mesh, const std::string& path);

// Reads a tet mesh (4- or 10-node) with named physical surfaces; InputError if the file cannot be
// read or holds no tetrahedra.
TetMesh read_msh(const std::string& path);

}  // namespace needle
