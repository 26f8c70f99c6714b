#include "mesher/vtk_files.h"

#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <cstdint>
#include <limits>

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
    std::ofstream out(scratch_path, std::ios::binary);
    out.precision(17);
    body(out);
    if (!out) throw std::runtime_error("could not write " + path);
  });
}

template <class T>
const char* vtk_type();
template <>
const char* vtk_type<double>() { return "Float64"; }
template <>
const char* vtk_type<std::int64_t>() { return "Int64"; }
template <>
const char* vtk_type<std::int32_t>() { return "Int32"; }
template <>
const char* vtk_type<std::uint8_t>() { return "UInt8"; }

// The raw bytes of a file's binary arrays, written after its XML in one <AppendedData encoding="raw"> block: each array
// its byte count (UInt64, the header_type) then its values, found by its offset from the block's first byte after '_'.
using AppendedData = std::string;

// One DataArray of the given values (row after row): as text, or as a reference into the appended data.
template <class T>
void write_array(std::ostream& out, AppendedData* appended, const std::string& name, int components, const std::vector<T>& values) {
  if (!appended) {
    out << fmt::format("        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n", vtk_type<T>(), name, components);
    for (const T& v : values) out << +v << ' ';  // + prints a UInt8 as a number
    out << "\n        </DataArray>\n";
    return;
  }
  static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559, "VTK's Float64 is an IEEE double");
  out << fmt::format("        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" offset=\"{}\"/>\n", vtk_type<T>(), name,
                     components, appended->size());
  const std::uint64_t bytes = values.size() * sizeof(T);  // little-endian machines only (x86-64, aarch64)
  appended->append(reinterpret_cast<const char*>(&bytes), sizeof bytes);
  appended->append(reinterpret_cast<const char*>(values.data()), static_cast<size_t>(bytes));
}

void write_field(std::ostream& out, AppendedData* appended, const VtkField& field, int padding_rows) {
  std::vector<double> values;
  values.reserve(static_cast<size_t>((field.values.rows() + padding_rows) * field.values.cols()));
  for (Eigen::Index r = 0; r < field.values.rows(); ++r)
    for (Eigen::Index c = 0; c < field.values.cols(); ++c) values.push_back(field.values(r, c));
  values.resize(values.size() + static_cast<size_t>(padding_rows * field.values.cols()), 0.0);
  write_array(out, appended, field.name, static_cast<int>(field.values.cols()), values);
}

void write_points(std::ostream& out, AppendedData* appended, const Eigen::MatrixX3d& X) {
  out << "      <Points>\n";
  write_field(out, appended, VtkField{"position_mm", X}, 0);
  out << "      </Points>\n";
}

// The appended block and the file's end.
void write_file_end(std::ostream& out, const AppendedData* appended) {
  if (appended) {
    out << "  <AppendedData encoding=\"raw\">\n_";
    out.write(appended->data(), static_cast<std::streamsize>(appended->size()));
    out << "\n  </AppendedData>\n";
  }
  out << "</VTKFile>\n";
}

std::string file_header(const char* type, VtkEncoding encoding) {
  return fmt::format("<?xml version=\"1.0\"?>\n<VTKFile type=\"{}\" version=\"1.0\" byte_order=\"LittleEndian\"{}>\n", type,
                     encoding == VtkEncoding::binary ? " header_type=\"UInt64\"" : "");
}

}  // namespace

void write_vtu(const std::string& path, const TetMesh& mesh, const std::vector<VtkField>& tet_fields,
               const std::vector<VtkField>& point_fields, VtkEncoding encoding) {
  for (const VtkField& f : tet_fields)
    if (f.values.rows() != mesh.num_tets()) throw std::logic_error("write_vtu: tet field " + f.name + " has the wrong size");
  for (const VtkField& f : point_fields)
    if (f.values.rows() != mesh.num_nodes()) throw std::logic_error("write_vtu: point field " + f.name + " has the wrong size");
  write_atomically(path, ".vtu", [&](std::ostream& out) {
    AppendedData data;
    AppendedData* const appended = encoding == VtkEncoding::binary ? &data : nullptr;
    const int tets = mesh.num_tets(), faces = mesh.num_boundary_faces();
    out << file_header("UnstructuredGrid", encoding) << "  <UnstructuredGrid>\n"
        << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", mesh.num_nodes(), tets + faces);
    write_points(out, appended, mesh.X);
    out << "      <Cells>\n";
    std::vector<std::int64_t> connectivity, offsets;
    std::vector<std::uint8_t> types;
    std::vector<std::int32_t> tags;
    for (int t = 0; t < tets; ++t) {
      for (int c = 0; c < mesh.T.cols(); ++c) connectivity.push_back(mesh.T(t, c));
      offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
      types.push_back(mesh.order == 2 ? 24 : 10);
      tags.push_back(-1);
    }
    for (int f = 0; f < faces; ++f) {
      for (int c = 0; c < mesh.boundary_faces.cols(); ++c) connectivity.push_back(mesh.boundary_faces(f, c));
      offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
      types.push_back(mesh.order == 2 ? 22 : 5);
      tags.push_back(mesh.boundary_tag(f));
    }
    write_array(out, appended, "connectivity", 1, connectivity);
    write_array(out, appended, "offsets", 1, offsets);
    write_array(out, appended, "types", 1, types);
    out << "      </Cells>\n      <CellData Scalars=\"boundary_tag\">\n";
    write_array(out, appended, "boundary_tag", 1, tags);
    for (const VtkField& f : tet_fields) write_field(out, appended, f, faces);
    out << "      </CellData>\n      <PointData>\n";
    for (const VtkField& f : point_fields) write_field(out, appended, f, 0);
    out << "      </PointData>\n    </Piece>\n  </UnstructuredGrid>\n";
    // The tag names, so that a reader knows which boundary_tag is which face.
    out << "  <!-- boundary_tag:";
    for (size_t i = 0; i < mesh.tag_names.size(); ++i) out << ' ' << i << '=' << mesh.tag_names[i];
    out << " -->\n";
    write_file_end(out, appended);
  });
}

void write_vtp(const std::string& path, const Eigen::MatrixX3d& points, const std::vector<VtkField>& point_fields, VtkEncoding encoding) {
  for (const VtkField& f : point_fields)
    if (f.values.rows() != points.rows()) throw std::logic_error("write_vtp: field " + f.name + " has the wrong size");
  write_atomically(path, ".vtp", [&](std::ostream& out) {
    AppendedData data;
    AppendedData* const appended = encoding == VtkEncoding::binary ? &data : nullptr;
    const Eigen::Index n = points.rows();
    out << file_header("PolyData", encoding) << "  <PolyData>\n"
        << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n", n, n);
    write_points(out, appended, points);
    out << "      <Verts>\n";
    std::vector<std::int64_t> connectivity(static_cast<size_t>(n)), offsets(static_cast<size_t>(n));
    for (Eigen::Index i = 0; i < n; ++i) {
      connectivity[static_cast<size_t>(i)] = i;
      offsets[static_cast<size_t>(i)] = i + 1;
    }
    write_array(out, appended, "connectivity", 1, connectivity);
    write_array(out, appended, "offsets", 1, offsets);
    out << "      </Verts>\n      <PointData>\n";
    for (const VtkField& f : point_fields) write_field(out, appended, f, 0);
    out << "      </PointData>\n    </Piece>\n  </PolyData>\n";
    write_file_end(out, appended);
  });
}

}  // namespace needle
