// gmsh needle meshes: volume and facet areas against the ideal solid, tags on every boundary face,
// T10 nodes where they belong, orientation, and the .msh round trip.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "geometry/exact_measures.h"
#include "core/input_error.h"
#include "geometry/tip_geometry.h"
#include "mesher/mesh_quality.h"
#include "mesher/msh_file.h"
#include "mesher/needle_mesher.h"
#include "mesher/vtk_files.h"

using namespace needle;

namespace {

TetMesh mesh_of(const std::string& preset, bool half, int order, double size_mm) {
  NeedleMeshOptions o;
  o.order = order;
  o.size_mm = size_mm;
  return mesh_needle(resolve_tip(preset_recipe(preset)), half, o);
}

std::array<int, 3> sorted3(int a, int b, int c) {
  std::array<int, 3> k{a, b, c};
  std::sort(k.begin(), k.end());
  return k;
}

Eigen::Vector3d X(const TetMesh& m, int i) { return m.X.row(i).transpose(); }

// The faces that belong to exactly one tet, found from the tets alone.
std::set<std::array<int, 3>> exposed_faces(const TetMesh& m) {
  std::map<std::array<int, 3>, int> count;
  for (int t = 0; t < m.num_tets(); ++t)
    for (int skip = 0; skip < 4; ++skip) {
      int f[3], n = 0;
      for (int c = 0; c < 4; ++c)
        if (c != skip) f[n++] = m.T(t, c);
      ++count[sorted3(f[0], f[1], f[2])];
    }
  std::set<std::array<int, 3>> exposed;
  for (const auto& [face, n] : count)
    if (n == 1) exposed.insert(face);
  return exposed;
}

}  // namespace

TEST_CASE("T10 meshes of the paper presets match the ideal solid's volume and facet areas", "[mesher][gmsh][slow]") {
  for (const std::string preset : {"SB", "LMB", "AMB", "HMB"}) {
    const TipGeometry tip = resolve_tip(preset_recipe(preset));
    const TetMesh mesh = mesh_of(preset, true, 2, 0.25);
    const MeshQuality q = measure_quality(mesh);
    ExactOptions exact;
    exact.half_model = true;
    INFO(preset << " volume " << q.volume_mm3 << " tets " << q.tets);
    CHECK(std::abs(q.volume_mm3 / exact_volume_mm3(tip, exact) - 1) < 0.005);
    CHECK(q.inverted_tets == 0);
    CHECK(q.min_scaled_jacobian > 0);
    for (size_t i = 0; i < tip.facets.size(); ++i) {
      const int tag = mesh.tag_index(tip.facets[i].name);
      if (tip.facets[i].normal.z() < -1e-9 && tip.facets[i].name.find("neg") != std::string::npos) {
        CHECK(tag < 0);  // the z < 0 side facets are not in the half model
        continue;
      }
      REQUIRE(tag >= 0);
      const double reference = exact_facet_area_mm2(tip, static_cast<int>(i), exact);
      INFO(tip.facets[i].name << " mesh " << q.boundary_area_by_tag_mm2[static_cast<size_t>(tag)] << " exact " << reference);
      CHECK(std::abs(q.boundary_area_by_tag_mm2[static_cast<size_t>(tag)] / reference - 1) < 0.005);
    }
  }
}

TEST_CASE("every boundary face of the mesh carries a tag, and only boundary faces do", "[mesher][gmsh][slow]") {
  for (const bool half : {true, false}) {
    const TetMesh mesh = mesh_of("LMB", half, 1, 0.3);
    std::set<std::array<int, 3>> tagged;
    for (int b = 0; b < mesh.num_boundary_faces(); ++b) {
      REQUIRE(mesh.boundary_tag(b) >= 0);
      REQUIRE(mesh.boundary_tag(b) < static_cast<int>(mesh.tag_names.size()));
      tagged.insert(sorted3(mesh.boundary_faces(b, 0), mesh.boundary_faces(b, 1), mesh.boundary_faces(b, 2)));
    }
    CHECK(tagged.size() == static_cast<size_t>(mesh.num_boundary_faces()));  // no face tagged twice
    CHECK(tagged == exposed_faces(mesh));
    std::set<std::string> names(mesh.tag_names.begin(), mesh.tag_names.end());
    std::set<std::string> expected = {"top", "bottom", "side_pos", "groove_floor", "groove_wall", "shaft", "base"};
    expected.insert(half ? "symmetry" : "side_neg");
    CHECK(names == expected);
    for (int b = 0; b < mesh.num_boundary_faces(); ++b)
      if (mesh.tag_names[static_cast<size_t>(mesh.boundary_tag(b))] == "symmetry")
        for (int c = 0; c < 3; ++c) CHECK(std::abs(mesh.X(mesh.boundary_faces(b, c), 2)) < 1e-12);
  }
}

TEST_CASE("tets are positive and boundary faces point outward (divergence theorem)", "[mesher][gmsh][slow]") {
  const TetMesh mesh = mesh_of("HMB", true, 1, 0.3);
  double volume_from_faces = 0, volume_from_tets = 0;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const double v = signed_tet_volume(X(mesh, mesh.T(t, 0)), X(mesh, mesh.T(t, 1)), X(mesh, mesh.T(t, 2)), X(mesh, mesh.T(t, 3)));
    REQUIRE(v > 0);
    volume_from_tets += v;
  }
  for (int b = 0; b < mesh.num_boundary_faces(); ++b) {
    const Eigen::Vector3d p0 = X(mesh, mesh.boundary_faces(b, 0)), p1 = X(mesh, mesh.boundary_faces(b, 1)),
                          p2 = X(mesh, mesh.boundary_faces(b, 2));
    volume_from_faces += p0.dot(p1.cross(p2)) / 6.0;
  }
  CHECK(volume_from_faces == Approx(volume_from_tets).epsilon(1e-10));
}

TEST_CASE("T10 nodes: shaft mid-edge nodes on the true cylinder, edge nodes in VTK order", "[mesher][gmsh][slow]") {
  const TipGeometry tip = resolve_tip(preset_recipe("SB"));
  const TetMesh mesh = mesh_of("SB", true, 2, 0.25);
  REQUIRE(mesh.order == 2);
  const int shaft = mesh.tag_index("shaft");
  double worst_radius_error = 0, worst_plane_distance = 0;
  int facet_faces = 0;
  for (int b = 0; b < mesh.num_boundary_faces(); ++b) {
    const std::string& tag = mesh.tag_names[static_cast<size_t>(mesh.boundary_tag(b))];
    for (int e = 0; e < 3; ++e) {
      const Eigen::Vector3d m = X(mesh, mesh.boundary_faces(b, 3 + e));
      if (mesh.boundary_tag(b) == shaft) worst_radius_error = std::max(worst_radius_error, std::abs(std::hypot(m.y(), m.z()) - tip.radius_mm));
    }
    for (const FacetPlane& f : tip.facets) {
      if (f.name != tag) continue;
      ++facet_faces;
      for (int c = 0; c < 6; ++c)
        worst_plane_distance = std::max(worst_plane_distance, std::abs(f.signed_distance(X(mesh, mesh.boundary_faces(b, c)))));
    }
  }
  INFO("shaft mid-edge radius error " << worst_radius_error << " mm; facet nodes off their plane " << worst_plane_distance << " mm");
  CHECK(worst_radius_error < 1e-3);  // the geometry's chord tolerance; gmsh puts them on the OCC cylinder
  CHECK(facet_faces > 20);
  CHECK(worst_plane_distance < 1e-9);  // all six nodes of a facet's face lie in the facet plane
  // Every tet mid-edge node lies near the midpoint of the edge VTK order says it belongs to.
  double worst_ratio = 0;
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int e = 0; e < 6; ++e) {
      const Eigen::Vector3d a = X(mesh, mesh.T(t, kTet10EdgeCorners[e][0])), c = X(mesh, mesh.T(t, kTet10EdgeCorners[e][1]));
      worst_ratio = std::max(worst_ratio, (X(mesh, mesh.T(t, 4 + e)) - 0.5 * (a + c)).norm() / (a - c).norm());
    }
  CHECK(worst_ratio < 0.25);
}

TEST_CASE("a mesh survives the .msh round trip with its tags, and .vtu is written whole", "[mesher][gmsh][io][slow]") {
  const TetMesh mesh = mesh_of("AMB", true, 2, 0.3);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "needle-msh-test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "amb.msh").string();
  write_msh(mesh, path);
  std::ifstream file(path);
  std::string line1, line2;
  std::getline(file, line1);
  std::getline(file, line2);
  CHECK(line1 == "$MeshFormat");
  CHECK(line2 == "4.1 0 8");
  const TetMesh back = read_msh(path);
  CHECK(back.order == 2);
  CHECK(back.num_nodes() == mesh.num_nodes());
  CHECK(back.num_tets() == mesh.num_tets());
  CHECK(back.num_boundary_faces() == mesh.num_boundary_faces());
  CHECK(back.tag_names == mesh.tag_names);
  CHECK((back.X - mesh.X).cwiseAbs().maxCoeff() < 1e-12);
  const std::vector<double> a = boundary_area_by_tag_mm2(mesh), b = boundary_area_by_tag_mm2(back);
  for (size_t i = 0; i < a.size(); ++i) CHECK(b[i] == Approx(a[i]).epsilon(1e-12));
  CHECK(tet_mesh_volume_mm3(back) == Approx(tet_mesh_volume_mm3(mesh)).epsilon(1e-12));

  write_vtu((dir / "amb.vtu").string(), mesh);
  std::ifstream vtu(dir / "amb.vtu");
  const std::string text((std::istreambuf_iterator<char>(vtu)), std::istreambuf_iterator<char>());
  CHECK(text.find("NumberOfPoints=\"" + std::to_string(mesh.num_nodes()) + "\"") != std::string::npos);
  CHECK(text.find("NumberOfCells=\"" + std::to_string(mesh.num_tets() + mesh.num_boundary_faces()) + "\"") != std::string::npos);
  CHECK(text.rfind("</VTKFile>") != std::string::npos);
  CHECK_THROWS_AS(read_msh((dir / "missing.msh").string()), InputError);
  std::ofstream((dir / "junk.msh").string()) << "not a mesh\n";
  CHECK_THROWS_AS(read_msh((dir / "junk.msh").string()), InputError);
  std::filesystem::remove_all(dir);
}

TEST_CASE("mesh_surface fills a closed tagged surface and keeps its tags", "[mesher][gmsh][slow]") {
  // A 2 x 1 x 1 mm box, two triangles per face, each face its own tag.
  TriSurface box;
  box.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) box.V.row(i) << 2.0 * (i & 1), (i >> 1) & 1, (i >> 2) & 1;
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  box.F.resize(12, 3);
  box.face_tag.resize(12);
  for (int q = 0; q < 6; ++q) {
    box.F.row(2 * q) << quads[q][0], quads[q][1], quads[q][2];
    box.F.row(2 * q + 1) << quads[q][0], quads[q][2], quads[q][3];
    box.face_tag(2 * q) = box.face_tag(2 * q + 1) = q;
    box.tag_names.push_back("face" + std::to_string(q));
  }
  NeedleMeshOptions o;
  o.order = 2;
  o.size_mm = 0.25;
  const TetMesh mesh = mesh_surface(box, o);
  CHECK(tet_mesh_volume_mm3(mesh) == Approx(2.0).epsilon(1e-12));
  const std::vector<double> areas = boundary_area_by_tag_mm2(mesh);
  REQUIRE(areas.size() == 6);
  CHECK(areas[0] == Approx(2.0).epsilon(1e-12));  // z = 0 face
  CHECK(areas[4] == Approx(1.0).epsilon(1e-12));  // x = 0 face
  CHECK(mesh.num_tets() > 50);                     // the interior was filled, not just split

  TriSurface open = box;
  open.F.conservativeResize(11, 3);
  open.face_tag.conservativeResize(11);
  CHECK_THROWS_AS(mesh_surface(open, o), InputError);
  TriSurface inverted = box;
  inverted.F.col(1).swap(inverted.F.col(2));
  CHECK_THROWS_AS(mesh_surface(inverted, o), InputError);
}

TEST_CASE("absurd mesh options are refused before gmsh runs", "[mesher][errors]") {
  const TipGeometry tip = resolve_tip(preset_recipe("LMB"));
  auto with = [](auto change) {
    NeedleMeshOptions o;
    change(o);
    return o;
  };
  CHECK_THROWS_AS(mesh_needle(tip, true, with([](NeedleMeshOptions& o) { o.size_mm = 0; })), InputError);
  CHECK_THROWS_AS(mesh_needle(tip, true, with([](NeedleMeshOptions& o) { o.size_mm = -0.2; })), InputError);
  CHECK_THROWS_AS(mesh_needle(tip, true, with([](NeedleMeshOptions& o) { o.size_mm = std::nan(""); })), InputError);
  CHECK_THROWS_AS(mesh_needle(tip, true, with([](NeedleMeshOptions& o) { o.size_mm = 0.001; })), InputError);
  CHECK_THROWS_AS(mesh_needle(tip, true, with([](NeedleMeshOptions& o) { o.size_mm = 5.0; })), InputError);
  CHECK_THROWS_AS(mesh_needle(tip, true, with([](NeedleMeshOptions& o) { o.order = 3; })), InputError);
  CHECK_THROWS_AS(mesh_needle(tip, true, with([](NeedleMeshOptions& o) { o.size_mm = 0.006; })), InputError);  // ~1e9 tets
}
