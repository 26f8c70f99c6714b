// `needle mesh` and `needle particles` end to end, as a user runs them.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include "cli_run.h"

#include "mesher/msh_file.h"

namespace fs = std::filesystem;

using needle_test::Result;
using needle_test::run;

TEST_CASE("needle mesh --preset LMB --order 2 --size-mm 0.2 --half writes a valid T10 mesh", "[apps][cli][mesher][slow]") {
  const fs::path dir = fs::temp_directory_path() / "needle-mesh-cli-test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string msh = (dir / "lmb.msh").string();
  const Result r = run("mesh --preset LMB --order 2 --size-mm 0.2 --half --out " + msh + " --out " + (dir / "lmb.vtu").string() + " --json");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["element"] == "T10");
  CHECK(std::abs(j["volume_error_rel"].get<double>()) < 0.005);
  CHECK(j["quality"]["inverted_tets"] == 0);
  for (const char* tag : {"top", "bottom", "side_pos", "groove_floor", "groove_wall", "shaft", "base", "symmetry"})
    CHECK(j["face_areas_mm2"].contains(tag));
  for (const auto& [name, exact] : j["facet_areas_exact_mm2"].items())
    if (j["face_areas_mm2"].contains(name))
      CHECK(std::abs(j["face_areas_mm2"][name].get<double>() / exact.get<double>() - 1) < 0.005);
  const needle::TetMesh mesh = needle::read_msh(msh);
  CHECK(mesh.order == 2);
  CHECK(mesh.num_tets() == j["tets"].get<int>());
  CHECK(mesh.num_nodes() == j["nodes"].get<int>());
  CHECK(fs::file_size(dir / "lmb.vtu") > 100000);
  fs::remove_all(dir);
}

TEST_CASE("needle mesh and needle particles refuse bad input and write nothing", "[apps][cli][errors][slow]") {
  const fs::path dir = fs::temp_directory_path() / "needle-mesh-cli-errors";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string d = dir.string();
  std::ofstream(dir / "open.stl") << "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                                      "endloop\nendfacet\nendsolid x\n";
  CHECK(run("mesh --surface " + d + "/open.stl --out " + d + "/a.msh").exit_code == 2);
  fs::remove(dir / "open.stl");
  CHECK(run("mesh --preset LMB --size-mm -1 --out " + d + "/b.msh").exit_code == 2);
  CHECK(run("mesh --preset LMB --size-mm 0.0001 --out " + d + "/c.msh").exit_code == 2);
  CHECK(run("mesh --preset LMB --order 3 --out " + d + "/d.msh").exit_code == 2);
  CHECK(run("mesh --preset LMB --out " + d + "/e.stl").exit_code == 2);
  CHECK(run("mesh --preset XYZ --out " + d + "/f.msh").exit_code == 2);
  CHECK(run("mesh --out " + d + "/g.msh").exit_code == 2);
  CHECK(run("particles --spacing-mm 0 --out " + d + "/p.vtp").exit_code == 2);
  CHECK(run("particles --faces free free fixed fixed glued fixed --out " + d + "/q.vtp").exit_code == 2);
  CHECK(run("particles --insert-mm 3 --out " + d + "/r.vtp").exit_code == 2);
  CHECK(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST_CASE("needle particles: the paper block, classified against an inserted needle", "[apps][cli][particles][slow]") {
  const fs::path dir = fs::temp_directory_path() / "needle-particles-cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Result r = run("particles --preset SB --insert-mm 4 --json --out " + (dir / "p.vtp").string());
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["particles"] == 101 * 21 * 6);
  CHECK(j["total_volume_mm3"].get<double>() == Approx(640.0).epsilon(1e-12));
  CHECK(j["needle"]["inside_particles"].get<int>() > 0);
  CHECK(fs::file_size(dir / "p.vtp") > 10000);
  fs::remove_all(dir);
}
