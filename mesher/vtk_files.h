#pragma once
// ParaView files in VTK's XML format: .vtu for tet meshes, .vtp for particles. ASCII by default, so that a
// person can read them too; binary for the run's frames: the XML first, each array a reference into one raw
// <AppendedData> block at the end (header_type UInt64: each array's byte count, then its bytes, little-endian), as
// VTK, ParaView and meshio read it. Raw rather than base64 inline: a quarter smaller and no encoding pass (a paper-scene
// particle frame at 0.2 mm near the path 6.6 MB instead of 8.9). Each file appears complete or not at all.
#include <Eigen/Dense>
#include <string>
#include <utility>
#include <vector>

#include "mesher/tet_mesh.h"

namespace needle {

enum class VtkEncoding { ascii, binary };

// A named data array: #rows values with 1 (scalar) or 3 (vector) components.
struct VtkField {
  std::string name;
  Eigen::MatrixXd values;  // #rows by 1 or 3
};

// Tets (VTK_TETRA / VTK_QUADRATIC_TETRA) followed by the boundary faces (VTK_TRIANGLE /
// VTK_QUADRATIC_TRIANGLE). Cell data: `boundary_tag` (-1 on tets) plus tet_fields (given per tet,
// written as 0 on the faces); point data: point_fields.
void write_vtu(const std::string& path, const TetMesh& mesh, const std::vector<VtkField>& tet_fields = {},
               const std::vector<VtkField>& point_fields = {}, VtkEncoding encoding = VtkEncoding::ascii);

// Points as VTK_VERTEX cells with point data.
void write_vtp(const std::string& path, const Eigen::MatrixX3d& points, const std::vector<VtkField>& point_fields = {},
               VtkEncoding encoding = VtkEncoding::ascii);

}  // namespace needle
