// Every exported format re-imports as a closed manifold with the same area and volume; broken input
// is refused with a reason.
#include <assimp/Importer.hpp>
#include <assimp/scene.h>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "geometry/cad_solid.h"
#include "core/input_error.h"
#include "geometry/mesh_io.h"
#include "geometry/surface_measures.h"

using namespace needle;
namespace fs = std::filesystem;

namespace {
fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("needle-test-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
}  // namespace

TEST_CASE("exported files re-import closed, manifold, with the same area and volume", "[geometry][io][slow]") {
  const CadSolid solid = build_cad_solid(preset_recipe("LMB"), true);
  const double area = surface_area_mm2(solid.surface), volume = enclosed_volume_mm3(solid.surface);
  const fs::path dir = fresh_dir("io");
  const std::vector<std::pair<std::string, bool>> files = {
      {"tip.stl", false}, {"tip_ascii.stl", true}, {"tip.obj", false}, {"tip.ply", false}, {"tip.glb", false}, {"tip.gltf", false}};
  for (const auto& [name, ascii] : files) {
    const std::string path = (dir / name).string();
    write_surface(solid.surface, path, surface_format_from_path(path, ascii));
    const TriSurface back = read_surface(path);
    INFO(name);
    CHECK(check_topology(back).closed_manifold());
    // The slivers without area in single precision are left out (9 of LMB's 7 253); the rest must all come back.
    CHECK(back.num_faces() <= solid.surface.num_faces());
    CHECK(back.num_faces() >= solid.surface.num_faces() - solid.surface.num_faces() / 500);
    // Files store single precision: relative changes of order 1e-7.
    CHECK(surface_area_mm2(back) == Approx(area).epsilon(1e-5));
    CHECK(enclosed_volume_mm3(back) == Approx(volume).epsilon(1e-5));
  }
  // OBJ and glTF keep the facet tags as mesh names.
  for (const std::string name : {"tip.obj", "tip.glb"}) {
    const TriSurface back = read_surface((dir / name).string());
    const std::vector<double> original = area_by_tag_mm2(solid.surface), areas = area_by_tag_mm2(back);
    for (const char* tag : {"top", "side_pos", "groove_floor", "symmetry"}) {
      INFO(name << " " << tag);
      REQUIRE(back.tag_index(tag) >= 0);
      CHECK(areas[back.tag_index(tag)] == Approx(original[solid.surface.tag_index(tag)]).epsilon(1e-5));
    }
  }
  // No scratch folders are left behind.
  for (const auto& entry : fs::directory_iterator(dir)) CHECK(entry.path().filename().string().rfind(".needle-partial", 0) != 0);
}

TEST_CASE("exported files hold no zero-area triangle: every face read back as written is a triangle with area", "[geometry][io]") {
  // The CAD's slivers can collapse in single precision (two corners at one float position); such a face
  // reads back as a line or a point. Counted here on the surface itself, and looked for in each file as
  // assimp reads it without any clean-up.
  const CadSolid solid = build_cad_solid(preset_recipe("SB"), true);
  int collapsed = 0;
  for (int f = 0; f < solid.surface.num_faces(); ++f) {
    Eigen::Vector3f p[3];
    for (int k = 0; k < 3; ++k) p[k] = solid.surface.V.row(solid.surface.F(f, k)).cast<float>().transpose();
    if (p[0] == p[1] || p[1] == p[2] || p[0] == p[2]) ++collapsed;
  }
  INFO(collapsed << " of " << solid.surface.num_faces() << " faces collapse in single precision");
  CHECK(collapsed > 0);  // the case this guards against exists in the presets
  const fs::path dir = fresh_dir("io_degenerate");
  for (const auto& [name, ascii] : std::vector<std::pair<std::string, bool>>{
           {"tip.stl", false}, {"tip_ascii.stl", true}, {"tip.obj", false}, {"tip.ply", false}, {"tip.glb", false}}) {
    const std::string path = (dir / name).string();
    write_surface(solid.surface, path, surface_format_from_path(path, ascii));
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(path, 0);
    REQUIRE(scene);
    long faces = 0, not_triangles = 0, zero_area = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh* mesh = scene->mMeshes[m];
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        ++faces;
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices != 3) {
          ++not_triangles;
          continue;
        }
        const aiVector3D a = mesh->mVertices[face.mIndices[0]], b = mesh->mVertices[face.mIndices[1]], c = mesh->mVertices[face.mIndices[2]];
        if (((b - a) ^ (c - a)).SquareLength() == 0) ++zero_area;
      }
    }
    INFO(name << ": " << faces << " faces, " << not_triangles << " not triangles, " << zero_area << " of zero area");
    CHECK(not_triangles == 0);
    CHECK(zero_area == 0);
    CHECK(faces <= solid.surface.num_faces() - collapsed);
    CHECK(faces >= solid.surface.num_faces() - solid.surface.num_faces() / 500);
    // Leaving the slivers out keeps the surface closed: corners the CAD left 1e-17 mm apart are welded first
    // (SB's half model had 4 open edges where three such corners met).
    CHECK(check_topology(read_surface(path)).closed_manifold());
  }
}

TEST_CASE("open, unreadable and inside-out surfaces are refused", "[geometry][io][errors]") {
  const fs::path dir = fresh_dir("bad-io");
  CadSolid solid = build_cad_solid(preset_recipe("SB"));
  // Open: drop one triangle.
  TriSurface open = solid.surface;
  open.F.conservativeResize(open.F.rows() - 1, 3);
  open.face_tag.conservativeResize(open.F.rows());
  write_surface(open, (dir / "open.stl").string(), SurfaceFormat::stl_binary);
  CHECK_THROWS_WITH(read_surface((dir / "open.stl").string()), Catch::Contains("not a closed"));
  // Inside out: flip every triangle.
  TriSurface flipped = solid.surface;
  flipped.F.col(1).swap(flipped.F.col(2));
  write_surface(flipped, (dir / "flipped.stl").string(), SurfaceFormat::stl_binary);
  CHECK_THROWS_WITH(read_surface((dir / "flipped.stl").string()), Catch::Contains("face inward"));
  // Not a mesh at all.
  std::ofstream((dir / "garbage.stl").string()) << "this is not an STL file\n";
  CHECK_THROWS_AS(read_surface((dir / "garbage.stl").string()), InputError);
  CHECK_THROWS_WITH(read_surface((dir / "missing.stl").string()), Catch::Contains("no such file"));
  CHECK_THROWS_WITH(surface_format_from_path("tip.step"), Catch::Contains("cannot tell the surface format"));
  // Two unit cubes overlapping by half a unit in x and y: each edge has two triangles, every one faces out, the
  // divergence theorem gives 2 where the solid is 1.875; the surface crosses itself and is refused.
  {
    std::ofstream obj((dir / "cubes.obj").string());
    for (const double shift : {0.0, 0.5}) {
      for (int k = 0; k < 8; ++k) obj << "v " << shift + (k & 1) << " " << shift + ((k >> 1) & 1) << " " << ((k >> 2) & 1) << "\n";
    }
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const int base : {1, 9})
      for (const auto& q : quads)
        obj << "f " << base + q[0] << " " << base + q[1] << " " << base + q[2] << "\nf " << base + q[0] << " " << base + q[2] << " "
            << base + q[3] << "\n";
  }
  CHECK_THROWS_WITH(read_surface((dir / "cubes.obj").string()), Catch::Contains("intersects itself"));
  // One of them alone is a closed box of volume 1, accepted.
  {
    std::ofstream obj((dir / "cube.obj").string());
    for (int k = 0; k < 8; ++k) obj << "v " << (k & 1) << " " << ((k >> 1) & 1) << " " << ((k >> 2) & 1) << "\n";
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) obj << "f " << 1 + q[0] << " " << 1 + q[1] << " " << 1 + q[2] << "\nf " << 1 + q[0] << " " << 1 + q[2] << " " << 1 + q[3] << "\n";
  }
  CHECK(enclosed_volume_mm3(read_surface((dir / "cube.obj").string())) == Approx(1.0));
}
