// `needle tip` end to end, as a user runs it: exit codes, JSON fields, files written or not.
#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include "cli_run.h"

namespace fs = std::filesystem;

using needle_test::Result;
using needle_test::run;

TEST_CASE("needle tip --preset LMB --json prints the report", "[apps][cli][slow]") {
  const Result r = run("tip --preset LMB --json");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["d_a_mm"].get<double>() == Approx(-0.22));
  CHECK(j["tip_point_mm"][1].get<double>() == Approx(-0.29));
  CHECK(j["groove"]["face_y_mm"].get<double>() == Approx(-0.07));
  CHECK(j["groove"]["start_mm"].get<double>() == Approx(3.0));
  CHECK(j["groove"]["length_mm"].get<double>() == Approx(22.0));
  REQUIRE(j["facets"].size() == 4);
  for (const auto& f : j["facets"]) {
    CHECK(f.contains("name"));
    CHECK(f["normal"].size() == 3);
    CHECK(f["point_mm"].size() == 3);
    CHECK(std::abs(f["area_mm2"].get<double>() / f["area_exact_mm2"].get<double>() - 1) < 0.005);
  }
}

TEST_CASE("needle tip --d-a writes every format, bad input writes nothing", "[apps][cli][errors][slow]") {
  const fs::path dir = fs::temp_directory_path() / "needle-cli-test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string d = dir.string();
  CHECK(run("tip --d-a -0.1 --top-tilt-deg 25 --half --out " + d + "/t.glb --png " + d + "/t.png").exit_code == 0);
  CHECK(fs::file_size(dir / "t.glb") > 1000);
  CHECK(fs::file_size(dir / "t.png") > 1000);
  CHECK(run("tip --analyze " + d + "/t.glb --json").exit_code == 0);
  // --analyze writes nothing, so an --out or --png beside it is refused rather than ignored.
  const auto analyze_out = run("tip --analyze " + d + "/t.glb --out " + d + "/u.stl", true);
  CHECK(analyze_out.exit_code == 2);
  CHECK(analyze_out.out.find("--analyze only reads and measures a surface") != std::string::npos);
  CHECK(!fs::exists(dir / "u.stl"));

  fs::remove_all(dir);
  fs::create_directories(dir);
  CHECK(run("tip --preset XYZ --out " + d + "/a.stl").exit_code == 2);
  CHECK(run("tip --d-a 0.9 --out " + d + "/b.stl --png " + d + "/b.png").exit_code == 2);
  CHECK(run("tip --preset SB --out " + d + "/c.step").exit_code == 2);
  CHECK(run("tip --preset SB --d-a 0.1").exit_code == 2);
  CHECK(run("tip --analyze " + d + "/nothing.stl").exit_code == 2);
  CHECK(run("tip --preset SB --out /nonexistent-folder/x.stl").exit_code == 2);
  CHECK(run("tip --bogus-flag").exit_code != 0);
  // --png writes PNG data: another extension is refused before any work, not written under the wrong name.
  const auto jpg = run("tip --preset SB --png " + d + "/t.jpg", true);
  CHECK(jpg.exit_code == 2);
  CHECK(jpg.out.find("--png writes a PNG picture and needs a .png file") != std::string::npos);
  // Absurd work is refused before any, with the estimate and the limit: a chord tolerance of 1e-12 mm asked for
  // 1.8 million segments around the rod (it grew past 8 GB), a section step of 1e-9 mm for 4e10 sections.
  const auto chord = run("tip --preset SB --chord-tolerance-mm 1e-12 --out " + d + "/chord.stl", true);
  CHECK(chord.exit_code == 2);
  CHECK(chord.out.find("segments around the rod") != std::string::npos);
  CHECK(chord.out.find("use a larger --chord-tolerance-mm") != std::string::npos);
  const auto sections = run("tip --preset SB --section-step-mm 1e-9 --out " + d + "/sections.stl", true);
  CHECK(sections.exit_code == 2);
  CHECK(sections.out.find("cross-sections over") != std::string::npos);
  CHECK(fs::is_empty(dir));
  // A library's error that echoes the file (assimp on an ASCII STL with one bad vertex: 2 MB) is cut to one bounded line.
  {
    std::ofstream bad(dir / "bad.stl");
    bad << "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 BAD\n  endloop\n endfacet\n";
    for (int k = 0; k < 20000; ++k)
      bad << " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\n";
    bad << "endsolid x\n";
  }
  const auto echoed = run("tip --analyze " + d + "/bad.stl", true);
  CHECK(echoed.exit_code == 2);
  CHECK(echoed.out.find("needle: error: cannot read") != std::string::npos);
  CHECK(echoed.out.find("more characters left out)") != std::string::npos);
  CHECK(echoed.out.size() < 1000);
  fs::remove(dir / "bad.stl");
  // --out naming a folder is refused before any work, and no scratch folder is left (it was, after a filesystem error).
  fs::create_directories(dir / "folder.stl");
  const auto folder = run("tip --preset SB --out " + d + "/folder.stl", true);
  CHECK(folder.exit_code == 2);
  CHECK(folder.out.find("is a folder: give the surface file's name") != std::string::npos);
  for (const auto& entry : fs::directory_iterator(dir)) CHECK(entry.path().filename().string().rfind(".needle-partial", 0) != 0);
  fs::remove_all(dir / "folder.stl");
  // A folder where a recipe file is named: the project's words, not the stream's ("basic_filebuf::underflow").
  fs::create_directories(dir / "recipe_folder");
  const auto recipe_folder = run("tip --recipe " + d + "/recipe_folder --out " + d + "/r.stl", true);
  CHECK(recipe_folder.exit_code == 2);
  CHECK(recipe_folder.out.find("cannot read the recipe '" + d + "/recipe_folder': it is a folder, not a file") != std::string::npos);
  fs::remove_all(dir / "recipe_folder");
  // The environment refusing a write (here /proc, where no folder can be made) is exit 4, in one line, not a crash.
  const auto proc = run("tip --preset SB --out /proc/needle_tip.stl", true);
  CHECK(proc.exit_code == 4);
  CHECK(proc.out.rfind("needle: cannot read or write a file: ", 0) == 0);
  CHECK(std::count(proc.out.begin(), proc.out.end(), '\n') == 1);
  // A fine tolerance within the limits still builds.
  CHECK(run("tip --preset SB --chord-tolerance-mm 1e-4 --out " + d + "/fine.stl").exit_code == 0);
}
