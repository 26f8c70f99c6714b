// Other projects' readers open what the toolkit writes: meshio (python3-meshio) and VTK (ParaView's, python3-paraview) read the
// exported surfaces (STL binary and ASCII, OBJ, PLY) with our triangles and area, gmsh reads the STL files, and VTK
// reads the T10 mesh (VTU) and the particle set (VTP) with their counts; VTK and meshio read our binary and ASCII
// VTU and VTP value for value (meshio: the VTU; it has no VTP reader).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <gmsh.h>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/cad_solid.h"
#include "geometry/mesh_io.h"
#include "geometry/surface_measures.h"
#include "mesher/gmsh_session.h"
#include "mesher/vtk_files.h"

using namespace needle;
namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("needle-test-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Runs a Python script with Debian's python3 (where python3-meshio and ParaView's vtk module live); its output.
std::string run_python(const fs::path& dir, const std::string& script) {
  std::ofstream(dir / "read.py") << script;
  FILE* pipe = popen(("/usr/bin/python3 " + (dir / "read.py").string() + " 2>&1").c_str(), "r");
  REQUIRE(pipe);
  std::string out;
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  pclose(pipe);
  return out;
}

const std::vector<std::pair<std::string, bool>> kSurfaceFiles = {{"tip.stl", false}, {"tip_ascii.stl", true}, {"tip.obj", false}, {"tip.ply", false}};

// Compares a reader's "triangles cells area" line with the surface written and what assimp reads back.
void check_counts(const std::string& out, const std::string& path, const TriSurface& written) {
  INFO(path << ": " << out);
  const TriSurface back = read_surface(path);  // what assimp reads: the faces that were written
  long triangles = 0, cells = 0;
  double area = 0;
  REQUIRE(std::sscanf(out.c_str(), "%ld %ld %lf", &triangles, &cells, &area) == 3);
  CHECK(triangles == back.num_faces());
  CHECK(cells == triangles);  // nothing but triangles
  CHECK(area == Approx(surface_area_mm2(written)).epsilon(1e-5));
}

}  // namespace

TEST_CASE("exported STL, ASCII STL, OBJ and PLY are read by meshio with our triangles and area", "[geometry][io][slow]") {
  const CadSolid solid = build_cad_solid(preset_recipe("SB"), true);
  const fs::path dir = fresh_dir("meshio");
  for (const auto& [name, ascii] : kSurfaceFiles) {
    const std::string path = (dir / name).string();
    write_surface(solid.surface, path, surface_format_from_path(path, ascii));
    check_counts(run_python(dir, "import meshio, numpy as np\n"
                                 "m = meshio.read('" + path + "')\n"
                                 "t = np.concatenate([c.data for c in m.cells if c.type == 'triangle'])\n"
                                 "p = m.points[t]\n"
                                 "print(len(t), sum(len(c.data) for c in m.cells), "
                                 "0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum())\n"),
                 path, solid.surface);
  }
}

TEST_CASE("exported STL, ASCII STL, OBJ and PLY are read by VTK with our triangles and area", "[geometry][io]") {
  // VTK's own readers, as ParaView opens these files; the area summed per triangle in double precision.
  const CadSolid solid = build_cad_solid(preset_recipe("SB"), true);
  const fs::path dir = fresh_dir("vtk_surfaces");
  for (const auto& [name, ascii] : kSurfaceFiles) {
    const std::string path = (dir / name).string();
    write_surface(solid.surface, path, surface_format_from_path(path, ascii));
    check_counts(run_python(dir, "import vtk\n"
                                 "path = '" + path + "'\n"
                                 "r = {'stl': vtk.vtkSTLReader, 'obj': vtk.vtkOBJReader, 'ply': vtk.vtkPLYReader}[path.rsplit('.', 1)[1]]()\n"
                                 "r.SetFileName(path)\n"
                                 "r.Update()\n"
                                 "d = r.GetOutput()\n"
                                 "tri = sum(1 for i in range(d.GetNumberOfCells()) if d.GetCellType(i) == vtk.VTK_TRIANGLE)\n"
                                 "area = sum(d.GetCell(i).ComputeArea() for i in range(d.GetNumberOfCells()) if d.GetCellType(i) == vtk.VTK_TRIANGLE)\n"
                                 "print(tri, d.GetNumberOfCells(), area)\n"),
                 path, solid.surface);
  }
}

TEST_CASE("exported STL, binary and ASCII, are read by gmsh with our triangles and area", "[geometry][io][gmsh]") {
  // gmsh reads STL (not OBJ or PLY) as a discrete surface of triangles.
  const CadSolid solid = build_cad_solid(preset_recipe("SB"), true);
  const fs::path dir = fresh_dir("gmsh_surfaces");
  for (const auto& [name, ascii] : std::vector<std::pair<std::string, bool>>{{"tip.stl", false}, {"tip_ascii.stl", true}}) {
    const std::string path = (dir / name).string();
    write_surface(solid.surface, path, surface_format_from_path(path, ascii));
    long triangles = 0, elements = 0;
    double area = 0;
    {
      const detail::GmshSession session("read_" + name);
      detail::gmsh_call("merging " + path, [&] { gmsh::merge(path); });
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> tags, nodes;
      gmsh::model::mesh::getElements(types, tags, nodes, 2);
      for (size_t k = 0; k < types.size(); ++k) {
        elements += static_cast<long>(tags[k].size());
        if (types[k] != 2) continue;  // 3-node triangles
        triangles += static_cast<long>(tags[k].size());
        for (size_t e = 0; e < tags[k].size(); ++e) {
          Eigen::Vector3d p[3];
          for (int c = 0; c < 3; ++c) {
            std::vector<double> coord, parametric;
            gmsh::model::mesh::getNode(nodes[k][3 * e + static_cast<size_t>(c)], coord, parametric);
            p[c] = Eigen::Vector3d(coord[0], coord[1], coord[2]);
          }
          area += 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
        }
      }
    }
    char line[200];
    std::snprintf(line, sizeof line, "%ld %ld %.17g", triangles, elements, area);
    check_counts(line, path, solid.surface);
  }
}

TEST_CASE("VTK reads the T10 mesh (VTU) and the particle set (VTP) the commands write, with their counts", "[geometry][io][gmsh]") {
  const fs::path dir = fresh_dir("vtk_volumes");
  const std::string needle = NEEDLE_BINARY;
  const std::string vtu = (dir / "sb.vtu").string(), vtp = (dir / "block.vtp").string();
  REQUIRE(std::system((needle + " mesh --preset SB --order 2 --size-mm 0.4 --half --out " + vtu + " --json > " + (dir / "mesh.json").string()).c_str()) == 0);
  REQUIRE(std::system((needle + " particles --out " + vtp + " --json > " + (dir / "particles.json").string()).c_str()) == 0);
  const std::string out = run_python(dir, "import vtk, json\n"
                                          "u = vtk.vtkXMLUnstructuredGridReader(); u.SetFileName('" + vtu + "'); u.Update(); g = u.GetOutput()\n"
                                          "tets = sum(1 for i in range(g.GetNumberOfCells()) if g.GetCellType(i) == vtk.VTK_QUADRATIC_TETRA)\n"
                                          "p = vtk.vtkXMLPolyDataReader(); p.SetFileName('" + vtp + "'); p.Update()\n"
                                          "print(g.GetNumberOfPoints(), tets, p.GetOutput().GetNumberOfPoints())\n");
  INFO(out);
  long nodes = 0, tets = 0, particles = 0;
  REQUIRE(std::sscanf(out.c_str(), "%ld %ld %ld", &nodes, &tets, &particles) == 3);
  nlohmann::json mesh, set;
  std::ifstream(dir / "mesh.json") >> mesh;
  std::ifstream(dir / "particles.json") >> set;
  INFO(mesh.dump().substr(0, 400) << "\n" << set.dump().substr(0, 400));
  CHECK(nodes == mesh.at("nodes").get<long>());
  CHECK(tets == mesh.at("tets").get<long>());
  CHECK(particles == set.at("particles").get<long>());
}

TEST_CASE("VTK and meshio read the binary and the ASCII VTU and VTP files value for value", "[geometry][io]") {
  const fs::path dir = fresh_dir("vtk_binary");
  // Two tets sharing a face, their four outer faces tagged; values with all 17 digits, a tiny and a huge one.
  TetMesh mesh;
  mesh.X.resize(5, 3);
  mesh.X << 0, 0, 0, 1.0 / 3, 0, 0, 0, 1, 0, 0, 0, 1, 1e-300, 2e300, -0.1;
  mesh.T.resize(2, 4);
  mesh.T << 0, 1, 2, 3, 1, 2, 3, 4;
  mesh.boundary_faces.resize(2, 3);
  mesh.boundary_faces << 0, 2, 1, 1, 2, 4;
  mesh.boundary_tag.resize(2);
  mesh.boundary_tag << 0, 1;
  mesh.tag_names = {"bottom", "side"};
  Eigen::MatrixXd per_tet(2, 1), per_node(5, 3);
  per_tet << M_PI, -std::exp(1.0);
  for (int i = 0; i < 5; ++i)
    for (int k = 0; k < 3; ++k) per_node(i, k) = std::sqrt(2.0 + i) * (k - 1) / 7.0;
  for (const auto& [name, encoding] : {std::pair{"binary", VtkEncoding::binary}, std::pair{"ascii", VtkEncoding::ascii}}) {
    const std::string vtu = (dir / (std::string(name) + ".vtu")).string(), vtp = (dir / (std::string(name) + ".vtp")).string();
    write_vtu(vtu, mesh, {{"pressure", per_tet}}, {{"velocity", per_node}}, encoding);
    write_vtp(vtp, mesh.X, {{"velocity", per_node}}, encoding);
    const std::string script =
        "import vtk, meshio\n"
        "from vtk.util.numpy_support import vtk_to_numpy\n"
        "u = vtk.vtkXMLUnstructuredGridReader(); u.SetFileName('" + vtu + "'); u.Update(); g = u.GetOutput()\n"
        "p = vtk.vtkXMLPolyDataReader(); p.SetFileName('" + vtp + "'); p.Update(); q = p.GetOutput()\n"
        "vals = list(vtk_to_numpy(g.GetPoints().GetData()).ravel()) + list(vtk_to_numpy(g.GetCellData().GetArray('pressure')).ravel())\n"
        "vals += list(vtk_to_numpy(g.GetPointData().GetArray('velocity')).ravel()) + list(vtk_to_numpy(q.GetPoints().GetData()).ravel())\n"
        "vals += list(vtk_to_numpy(q.GetPointData().GetArray('velocity')).ravel())\n"
        "vals += list(vtk_to_numpy(g.GetCellData().GetArray('boundary_tag')).ravel())\n"
        "vals += [g.GetCellType(i) for i in range(g.GetNumberOfCells())] + [g.GetCell(1).GetPointId(3), q.GetNumberOfVerts()]\n"
        "m = meshio.read('" + vtu + "')\n"
        "vals += list(m.points.ravel()) + list(m.point_data['velocity'].ravel())\n"
        "print(' '.join(repr(float(v)) for v in vals))\n";
    const std::string out = run_python(dir, script);
    INFO(name << ": " << out);
    std::vector<double> expected;
    const auto add = [&expected](const Eigen::MatrixXd& m) {
      for (Eigen::Index r = 0; r < m.rows(); ++r)
        for (Eigen::Index c = 0; c < m.cols(); ++c) expected.push_back(m(r, c));
    };
    add(mesh.X);
    add(Eigen::MatrixXd((Eigen::MatrixXd(4, 1) << per_tet, Eigen::MatrixXd::Zero(2, 1)).finished()));  // 0 on the faces
    add(per_node);
    add(mesh.X);
    add(per_node);
    for (double v : {-1.0, -1.0, 0.0, 1.0, 10.0, 10.0, 5.0, 5.0, 4.0, 5.0}) expected.push_back(v);
    add(mesh.X);
    add(per_node);
    std::vector<double> read;
    std::istringstream words(out);
    for (double v; words >> v;) read.push_back(v);
    REQUIRE(read.size() == expected.size());
    for (size_t i = 0; i < read.size(); ++i) {
      INFO("value " << i);
      CHECK(read[i] == expected[i]);  // both encodings carry every bit
    }
  }
  // The binary files hold their arrays raw, after the XML: each array's bytes once, not base64's four for three.
  for (const char* file : {"binary.vtu", "binary.vtp"}) {
    std::ifstream in(dir / file, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    INFO(file);
    CHECK(text.find("<AppendedData encoding=\"raw\">") != std::string::npos);
    CHECK(text.find("format=\"appended\"") != std::string::npos);
    CHECK(text.find("format=\"binary\"") == std::string::npos);
    // The positions' 15 doubles appear as their own bytes.
    std::string positions;
    for (Eigen::Index r = 0; r < mesh.X.rows(); ++r)
      for (int c = 0; c < 3; ++c) {
        const double v = mesh.X(r, c);
        positions.append(reinterpret_cast<const char*>(&v), sizeof v);
      }
    CHECK(text.find(positions) != std::string::npos);
  }
}
