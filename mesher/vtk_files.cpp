#include "mesher/vtk_files.h"

#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <functional>

#include "core/input_error.h"
#include "geometry/mesh_io.h"

namespace needle {
namespace {

namespace fs = std::filesystem;

// Writes a text file through a scratch file that is renamed into place once complete.
template <class Body>
void write_atomically(const std::string& path, const std::string& extension, Body body) {
  NEEDLE_REQUIRE(fs::path(path).extension() == extension, fmt::format("'{}' must end in {}", path, extension));
  write_file_atomically(path, [&](const std::string& scratch_path) {
    std::ofstream out(scratch_path);
    out.precision(17);
    body(out);
    if (!out) throw std::runtime_error("could not write " + path);
  });
}

void write_array(std::ostream& out, const std::string& type, const std::string& name, int components,
                 const std::function<void(std::ostream&)>& values) {
  out << fmt::format("        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n", type, name, components);
  values(out);
  out << "\n        </DataArray>\n";
}

void write_field(std::ostream& out, const VtkField& field, int padding_rows) {
  write_array(out, "Float64", field.name, static_cast<int>(field.values.cols()), [&](std::ostream& o) {
    for (Eigen::Index r = 0; r < field.values.rows(); ++r)
      for (Eigen::Index c = 0; c < field.values.cols(); ++c) o << field.values(r, c) << ' ';
    for (int r = 0; r < padding_rows * field.values.cols(); ++r) o << "0 ";
  });
}

void write_points(std::ostream& out, const Eigen::MatrixX3d& X) {
  out << "      <Points>\n";
  write_array(out, "Float64", "position_mm", 3, [&](std::ostream& o) {
    for (Eigen::Index i = 0; i < X.rows(); ++i) o << X(i, 0) << ' ' << X(i, 1) << ' ' << X(i, 2) << ' ';
  });
  out << "      </Points>\n";
}

}  // namespace

void write_vtu(const std::string& path, const TetMesh& mesh, const std::vector<VtkField>& tet_fields,
               const std::vector<VtkField>& point_fields) {
  for (const VtkField& f : tet_fields)
    if (f.values.rows() != mesh.num_tets()) throw std::logic_error("write_vtu: tet field " + f.name + " has the wrong size");
  for (const VtkField& f : point_fields)
    if (f.values.rows() != mesh.num_nodes()) throw std::logic_error("write_vtu: point field " + f.name + " has the wrong size");
  write_atomically(path, ".vtu", [&](std::ostream& out) {
    const int tets = mesh.num_tets(), faces = mesh.num_boundary_faces();
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
        << "  <UnstructuredGrid>\n"
        << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", mesh.num_nodes(), tets + faces);
    write_points(out, mesh.X);
    out << "      <Cells>\n";
    write_array(out, "Int64", "connectivity", 1, [&](std::ostream& o) {
      for (int t = 0; t < tets; ++t)
        for (int c = 0; c < mesh.T.cols(); ++c) o << mesh.T(t, c) << ' ';
      for (int f = 0; f < faces; ++f)
        for (int c = 0; c < mesh.boundary_faces.cols(); ++c) o << mesh.boundary_faces(f, c) << ' ';
    });
    write_array(out, "Int64", "offsets", 1, [&](std::ostream& o) {
      long offset = 0;
      for (int t = 0; t < tets; ++t) o << (offset += mesh.T.cols()) << ' ';
      for (int f = 0; f < faces; ++f) o << (offset += mesh.boundary_faces.cols()) << ' ';
    });
    write_array(out, "UInt8", "types", 1, [&](std::ostream& o) {
      for (int t = 0; t < tets; ++t) o << (mesh.order == 2 ? 24 : 10) << ' ';
      for (int f = 0; f < faces; ++f) o << (mesh.order == 2 ? 22 : 5) << ' ';
    });
    out << "      </Cells>\n      <CellData Scalars=\"boundary_tag\">\n";
    write_array(out, "Int32", "boundary_tag", 1, [&](std::ostream& o) {
      for (int t = 0; t < tets; ++t) o << "-1 ";
      for (int f = 0; f < faces; ++f) o << mesh.boundary_tag(f) << ' ';
    });
    for (const VtkField& f : tet_fields) write_field(out, f, faces);
    out << "      </CellData>\n      <PointData>\n";
    for (const VtkField& f : point_fields) write_field(out, f, 0);
    out << "      </PointData>\n    </Piece>\n  </UnstructuredGrid>\n";
    // The tag names, so that a reader knows which boundary_tag is which face.
    out << "  <!-- boundary_tag:";
    for (size_t i = 0; i < mesh.tag_names.size(); ++i) out << ' ' << i << '=' << mesh.tag_names[i];
    out << " -->\n</VTKFile>\n";
  });
}

void write_vtp(const std::string& path, const Eigen::MatrixX3d& points, const std::vector<VtkField>& point_fields) {
  for (const VtkField& f : point_fields)
    if (f.values.rows() != points.rows()) throw std::logic_error("write_vtp: field " + f.name + " has the wrong size");
  write_atomically(path, ".vtp", [&](std::ostream& out) {
    const Eigen::Index n = points.rows();
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
        << "  <PolyData>\n"
        << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n", n, n);
    write_points(out, points);
    out << "      <Verts>\n";
    write_array(out, "Int64", "connectivity", 1, [&](std::ostream& o) {
      for (Eigen::Index i = 0; i < n; ++i) o << i << ' ';
    });
    write_array(out, "Int64", "offsets", 1, [&](std::ostream& o) {
      for (Eigen::Index i = 0; i < n; ++i) o << i + 1 << ' ';
    });
    out << "      </Verts>\n      <PointData>\n";
    for (const VtkField& f : point_fields) write_field(out, f, 0);
    out << "      </PointData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  });
}

}  // namespace needle
