// Scene files and `needle simulate` as a user runs them: a small scene end to end, the run folder's
// contents checked against the solver's own invariants, and bad scenes refused with file, line and
// key, leaving no folder behind. Also `needle stiffness --json` and `needle run`'s coupled run folder; its scene
// flags are tested in test_run_scene_flags.cpp.
#include <algorithm>
#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <cstdlib>
#include <sstream>

#include "runs/csv_table.h"
#include "runs/scene.h"
#include "runs/scene_needle.h"
#include "cli_run.h"
#include "run_fixtures.h"
#include "core/input_error.h"

namespace fs = std::filesystem;
using namespace needle_test;

TEST_CASE("Scenes: paper defaults, units, and the effective scene reads back the same", "[apps][scene]") {
  const needle::Scene paper = needle::parse_scene("{}", "scene.json");
  CHECK(paper.needle.preset == "SB");
  CHECK(paper.motion.travel_mm == 30.0);
  CHECK(paper.motion.speed_mm_per_ms == 8.0);
  CHECK(paper.motion.accel_time_ms == 0.75);
  CHECK(paper.cannula.outer_diameter_mm == 1.27);
  CHECK(paper.cannula.wall_mm == 0.05);
  CHECK(paper.needle.material.youngs_modulus_MPa == 193000.0);
  CHECK(paper.needle.mesh.order == 2);
  CHECK(paper.needle.mesh.size_mm == 0.2);
  CHECK(paper.tissue.spacing_mm == 0.4);
  CHECK(paper.tissue.size_mm == Eigen::Vector3d(40, 8, 2));
  // A value with its unit in the string is converted; the suffixed key takes a number.
  const needle::Scene s = needle::parse_scene(
      R"({"motion": {"travel": "2.5 cm", "speed": "8000 mm/s", "accel_time": "750 us"},
          "needle": {"d_a": "-220 um", "material": {"youngs_modulus": "190 GPa", "density": "7900 kg/m3"}}})",
      "scene.json");
  CHECK(s.motion.travel_mm == Approx(25.0));
  CHECK(s.motion.speed_mm_per_ms == Approx(8.0));
  CHECK(s.motion.accel_time_ms == Approx(0.75));
  CHECK(s.needle.d_a_mm == Approx(-0.22));
  CHECK(s.needle.material.youngs_modulus_MPa == Approx(190000.0));
  CHECK(s.needle.material.density_g_per_mm3 == Approx(7.9e-3));
  const needle::Scene back = needle::parse_scene(needle::scene_to_json(s).dump(), "effective.json");
  CHECK(needle::scene_to_json(back) == needle::scene_to_json(s));
}

TEST_CASE("Every stored scene in data/scenes reads, and its effective scene reads back the same", "[apps][scene]") {
  // The scenes the docs' studies name (spacing study, the paper's own): a key renamed in
  // the reader, or a value it now refuses, fails here rather than in an hour-long run.
  int read = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(NEEDLE_SOURCE_DIR) / "data" / "scenes")) {
    if (entry.path().extension() != ".json") continue;
    INFO(entry.path().string());
    needle::Scene scene;
    REQUIRE_NOTHROW(scene = needle::read_scene(entry.path().string()));
    CHECK(scene.tissue.material.E_MPa > 0);
    const needle::Scene back = needle::parse_scene(needle::scene_to_json(scene).dump(), "effective.json");
    CHECK(needle::scene_to_json(back) == needle::scene_to_json(scene));
    ++read;
  }
  CHECK(read >= 4);
}

TEST_CASE("Bad scenes name the file, the line and the key", "[apps][scene]") {
  std::string m = message_of("{\n  \"motion\": {\n    \"travle_mm\": 30\n  }\n}");
  CHECK(m.find("scene.json:3") != std::string::npos);
  CHECK(m.find("motion.travle_mm") != std::string::npos);
  CHECK(m.find("unknown key") != std::string::npos);
  m = message_of("{\"needle\": {\n \"material\": {\n\n \"youngs_modulus_MPa\": -193000}}}");
  CHECK(m.find("scene.json:4") != std::string::npos);
  CHECK(m.find("needle.material.youngs_modulus_MPa must be positive") != std::string::npos);
  m = message_of("{\"motion\": {\"travel\": 30}}");
  CHECK(m.find("motion.travel") != std::string::npos);
  CHECK(m.find("needs a unit") != std::string::npos);
  m = message_of("{\"motion\": {\"travel\": \"30 MPa\"}}");
  CHECK(m.find("is not a length") != std::string::npos);
  m = message_of("{\"needle\": {\"mesh_file\": \"no_such.msh\"}}");
  CHECK(m.find("needle.mesh_file") != std::string::npos);
  CHECK(m.find("does not exist") != std::string::npos);
  m = message_of("{\"motion\": {\"travel_mm\": 30,\n \"speed_m_per_s\": 8,, }}");
  CHECK(m.find("scene.json:2") != std::string::npos);
  CHECK(m.find("not valid JSON") != std::string::npos);
  m = message_of("{\"needle\": {\"preset\": \"SB\", \"d_a_mm\": 0}}");
  CHECK(m.find("give one of") != std::string::npos);
  m = message_of("{\"cannula\": {\"wall_mm\": 0.7}}");
  CHECK(m.find("no bore") != std::string::npos);
}

TEST_CASE("needle --version names the version and the commit the binary was built from", "[apps]") {
  const auto version = run("--version");
  REQUIRE(version.exit_code == 0);
  INFO(version.out);
  CHECK(version.out.rfind("needle 0.", 0) == 0);
  // Built in a git work tree (a clone, as CI builds it): the commit is the work tree's HEAD, looked up independently here.
  const fs::path source(NEEDLE_SOURCE_DIR);
  if (fs::exists(source / ".git")) {
    FILE* pipe = popen(("git -C " + source.string() + " rev-parse --short=12 HEAD 2>/dev/null").c_str(), "r");
    REQUIRE(pipe);
    char buffer[64] = {0};
    const size_t n = fread(buffer, 1, sizeof buffer - 1, pipe);
    pclose(pipe);
    const std::string head = std::string(buffer, n).substr(0, 12);
    if (head.size() == 12) CHECK(version.out.find("(commit " + head) != std::string::npos);
  }
}

TEST_CASE("needle simulate: bad scenes exit non-zero and leave no run folder", "[apps][scene][slow]") {
  const fs::path dir = fresh_folder("bad");
  const std::vector<std::string> scenes = {
      R"({"motion": {"sped_m_per_s": 8}})", R"({"needle": {"material": {"youngs_modulus_MPa": -1}}})",
      R"({"needle": {"mesh_file": "missing.msh"}})", R"({"motion": {"travel": 30}})", R"({"tissue": {"enabled": true, "contact": {"stifness_factor": 5}}})"};
  for (size_t i = 0; i < scenes.size(); ++i) {
    write(dir / "scene.json", scenes[i]);
    const auto r = run("simulate " + (dir / "scene.json").string() + " --out " + (dir / "run").string(), true);
    INFO(scenes[i] << " -> " << r.out);
    CHECK(r.exit_code == 2);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);  // one clear line
    CHECK(r.out.find("scene.json") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "run"));
    CHECK_FALSE(fs::exists(dir / ".run.partial"));
  }
}

TEST_CASE("needle simulate: a rod pushed through the cannula writes a complete run folder", "[apps][scene][gmsh][slow]") {
  const fs::path dir = fresh_folder("rod");
  write(dir / "scene.json", R"({
    "needle": {"plain_rod": true, "length_mm": 20, "mesh": {"order": 1, "size_mm": 0.5}},
    "motion": {"travel_mm": 4},
    "solver": {"mass_scaling_dt_ms": 4e-5},
    "output": {"frames": 3, "history_interval_ms": 0.05}
  })");
  const auto r = run("simulate " + (dir / "scene.json").string() + " --out " + (dir / "run").string() + " --quiet");
  REQUIRE(r.exit_code == 0);
  for (const char* f : {"scene.json", "history.csv", "summary.json", "needle.pvd", "run.log", "frames/needle_0003.vtu"})
    CHECK(fs::is_regular_file(dir / "run" / f));
  nlohmann::json summary;
  std::ifstream(dir / "run" / "summary.json") >> summary;
  CHECK(summary["status"] == "finished");
  CHECK(summary["insertion_mm"].get<double>() == Approx(4.0));
  CHECK(summary["energy_balance_error"].get<double>() < 0.005);
  CHECK(std::abs(summary["deflection_mm"].get<double>()) < 1e-3);
  CHECK(summary["tip_displacement_mm"][0].get<double>() == Approx(4.0).epsilon(1e-3));
  // The run names the code that made it, as `needle --version` does.
  const auto version = run("--version");
  REQUIRE(version.exit_code == 0);
  CHECK(version.out.find("(commit " + summary["provenance"]["commit"].get<std::string>()) != std::string::npos);
  CHECK(version.out.find("needle " + summary["provenance"]["version"].get<std::string>() + " ") == 0);
  // The history's last row matches the summary, and its drive work equals KE + strain energy.
  std::ifstream csv(dir / "run" / "history.csv");
  std::string header, line, last;
  std::getline(csv, header);
  int rows = 0;
  while (std::getline(csv, line)) last = line, ++rows;
  CHECK(rows > 10);
  std::vector<double> v;
  std::stringstream ss(last);
  for (std::string cell; std::getline(ss, cell, ',');) v.push_back(std::stod(cell));
  REQUIRE(v.size() == 17);
  CHECK(v[1] == Approx(4.0));
  CHECK(v[5] == Approx(summary["deflection_mm"].get<double>()).margin(1e-12));
  CHECK(v[9] + v[10] == Approx(v[11] + v[12]).epsilon(0.005));
  // The effective scene runs again to the same result, and an existing folder is refused.
  const auto again = run("simulate " + (dir / "run" / "scene.json").string() + " --out " + (dir / "run").string() + " --quiet");
  CHECK(again.exit_code == 2);
  // Written with a trailing slash, as a shell's completion gives it: the folder run2, no stray .partial left.
  const auto replay = run("simulate " + (dir / "run" / "scene.json").string() + " --out " + (dir / "run2").string() + "/ --quiet", true);
  INFO(replay.out);
  REQUIRE(replay.exit_code == 0);
  nlohmann::json summary2;
  std::ifstream(dir / "run2" / "summary.json") >> summary2;
  CHECK(summary2["deflection_mm"].get<double>() == Approx(summary["deflection_mm"].get<double>()).margin(1e-12));
  CHECK(!fs::exists(dir / ".run2.partial"));
  const auto existing = run("simulate " + (dir / "run" / "scene.json").string() + " --out " + (dir / "run2").string() + "/ --quiet", true);
  CHECK(existing.exit_code == 2);  // and an existing one is refused, slash or not
}

TEST_CASE("needle stiffness --json reports compliance and frequencies with the beam reference", "[apps][needle][gmsh][slow]") {
  const auto r = run("stiffness --plain-rod --free-length-mm 30 --size-mm 0.3 --json");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  // 4 L^3 / (3 E pi r^4) for the plain rod, computed here.
  const double reference = 30.0 * 30.0 * 30.0 / (3 * 193000.0 * M_PI * 0.0625 / 4);
  CHECK(j["compliance_y_mm_per_N"].get<double>() == Approx(reference).epsilon(0.03));
  CHECK(j["beam_theory"]["compliance_y_mm_per_N"].get<double>() == Approx(reference).epsilon(1e-6));
  CHECK(j["frequency_y_hz"].get<double>() > 0);
  CHECK(run("stiffness --plain-rod --free-length-mm -3").exit_code == 2);
  CHECK(run("stiffness --preset XX").exit_code == 2);
}

TEST_CASE("needle run: a rod pushed into a small tissue block writes the coupled run folder", "[apps][lspg][gmsh][slow]") {
  const fs::path dir = fresh_folder("insertion");
  const auto r = run_rod_into_block(dir, R"({"size_mm": [2, 2.4, 1.2], "spacing_mm": 0.4})", 1.0, 2);
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  for (const char* file : {"scene.json", "history.csv", "facet_forces.csv", "summary.json", "needle.pvd", "tissue.pvd", "run.log",
                           "frames/tissue_0002.vtp", "frames/needle_0002.vtu"})
    CHECK(fs::exists(dir / "run" / file));
  std::ifstream in(dir / "run" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  CHECK(summary["status"] == "finished");
  CHECK(summary["insertion_mm"].get<double>() == Approx(1.0));
  CHECK(summary["particles_inside"].get<int>() == 0);
  CHECK(summary["energy_balance_error"].get<double>() < 0.02);
  CHECK(summary["steps"].get<long>() < summary["needle_steps"].get<long>());  // the needle subcycled
  for (const char* key : {"deflection_mm", "runtime_s", "peak_memory_MiB", "max_penetration_mm", "max_energy_balance_error"})
    CHECK(summary.contains(key));
  // The tissue frames carry the particle fields.
  std::ifstream vtp(dir / "run" / "frames" / "tissue_0002.vtp");
  const std::string text((std::istreambuf_iterator<char>(vtp)), std::istreambuf_iterator<char>());
  for (const char* field : {"displacement_mm", "plastic_strain", "broken_bonds", "in_contact"}) CHECK(text.find(field) != std::string::npos);
}

TEST_CASE("needle run: the worker threads do not change a run, bit for bit", "[apps][lspg][gmsh][threads][slow]") {
  // Every per-particle kernel is a gather (core/parallel.h): each index writes only its own outputs, so the
  // schedule cannot change a sum's order. The same coupled run on one and on two threads must give the same
  // history, every column of every row, exactly; `paper` and `calibrate` reuse runs across thread counts on this.
  const RunFiles one = run_rod_into_small_block("threads_1", "--threads 1");
  const RunFiles two = run_rod_into_small_block("threads_2", "--threads 2");
  REQUIRE(one.history.columns == two.history.columns);
  REQUIRE(one.history.rows.size() == two.history.rows.size());
  REQUIRE(one.history.rows.size() >= 5);
  size_t differing = 0;
  for (size_t i = 0; i < one.history.rows.size(); ++i) differing += one.history.rows[i] != two.history.rows[i];
  CHECK(differing == 0);
  CHECK(one.summary["deflection_mm"].get<double>() == two.summary["deflection_mm"].get<double>());
  CHECK(one.summary["bonds_broken"] == two.summary["bonds_broken"]);
  CHECK(one.summary["bonds_broken"].get<long>() > 0);  // the run cut the tissue: the failure and cut kernels ran
  CHECK(std::abs(one.summary["deflection_mm"].get<double>()) > 0);
}

TEST_CASE("needle run: path_refinement puts finer particles around the needle's path only", "[apps][lspg][gmsh][slow]") {
  // Block x 0..2, y -1.2..1.2, z 0..1.2 at 0.4 mm; within |y|, z <= 0.4 mm of the path the spacing halves.
  // Along x the refined band covers the whole length: 2 / 0.2 = 10 intervals. Along y: 0.8 mm at 0.2 and
  // 1.6 mm at 0.4 = 8. Along z: 0.4 at 0.2 and 0.8 at 0.4 = 4. Lattice nodes: 11 x 9 x 5.
  const fs::path dir = fresh_folder("insertion_refined");
  const auto r = run_rod_into_block(dir, R"({"size_mm": [2, 2.4, 1.2], "spacing_mm": 0.4, "path_refinement": 2, "path_half_width_mm": 0.4})",
                                    0.5, 0);
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  std::ifstream in(dir / "run" / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  CHECK(summary["status"] == "finished");
  CHECK(summary["particles"].get<int>() == 11 * 9 * 5);
  CHECK(summary.contains("bonds_cut_by_needle"));
  // A band wider than the block is refused before anything is written.
  write(dir / "wide.json", R"({"needle": {"plain_rod": true}, "tissue": {"size_mm": [2, 2.4, 1.2], "path_refinement": 2, "path_half_width_mm": 1.5}})");
  const auto wide = run("run --scene " + (dir / "wide.json").string() + " --out " + (dir / "wide").string() + " --quiet", true);
  CHECK(wide.exit_code == 2);
  CHECK_FALSE(fs::exists(dir / "wide"));
}

TEST_CASE("needle run: no needle, two needles or a bad number exit 2 with one line and no folder", "[apps][lspg][slow]") {
  const fs::path dir = fresh_folder("run_bad");
  for (const std::string& args : {"run --out " + (dir / "a").string(), "run --preset SB --d-a 0 --out " + (dir / "a").string(),
                                 "run --preset SB --travel-mm -3 --out " + (dir / "a").string(),
                                 "run --preset XX --out " + (dir / "a").string(),
                                 "run --preset SB --path-refinement 9 --out " + (dir / "a").string(),
                                 "run --preset SB --path-refinement 0 --out " + (dir / "a").string(),
                                 "run --preset SB --tissue-nu 0.5 --out " + (dir / "a").string(),
                                 "run --preset SB --tissue-friction -0.1 --out " + (dir / "a").string(),
                                 "run --preset SB --tissue-law neo_hookean --out " + (dir / "a").string(),
                                 "run --preset SB --speed-m-per-s 0 --out " + (dir / "a").string(),
                                 "run --preset SB --speed-m-per-s 100 --out " + (dir / "a").string(),
                                 "run --preset SB --hold-ms -1 --out " + (dir / "a").string(),
                                 "run --preset SB --decel-time-ms 10 --out " + (dir / "a").string()}) {
    const auto r = run(args, true);
    INFO(args << " -> " << r.out);
    CHECK(r.exit_code == 2);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(dir / "a"));
  }
}


TEST_CASE("needle run refuses an existing output folder before it builds anything and leaves the folder as it was", "[apps][sim]") {
  // The folder was checked only when the model had been built (2-3 s of CAD, meshing and particles); the one
  // line of the error, without the tissue note printed after the build, shows that nothing was built first.
  const fs::path dir = fresh_folder("run_existing");
  fs::create_directories(dir / "mine");
  write(dir / "mine" / "notes.txt", "keep me");
  for (const std::string& flags : {std::string(""), std::string(" --overwrite")}) {
    const auto r = run("run --preset SB --out " + (dir / "mine").string() + flags, true);
    INFO(flags << " -> " << r.out);
    CHECK(r.exit_code == 2);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
    CHECK(r.out.find(flags.empty() ? "already exists" : "replaces only a run folder this toolkit wrote") != std::string::npos);
    CHECK(r.out.find("tissue E") == std::string::npos);
    CHECK(fs::exists(dir / "mine" / "notes.txt"));
    CHECK_FALSE(fs::exists(dir / ".mine.partial"));
  }
}

TEST_CASE("needle simulate --overwrite replaces only a run folder the toolkit wrote, never the current folder or one above it", "[apps][sim][gmsh][slow]") {
  // A needle-alone scene of a fraction of a second.
  const fs::path dir = fresh_folder("overwrite_guard");
  write(dir / "scene.json", R"({"needle": {"plain_rod": true, "length_mm": 6, "mesh": {"order": 1, "size_mm": 0.5}},)"
                            R"("motion": {"accel_time_ms": 0.02, "travel_mm": 0.1}, "cannula": {"enabled": false}, "output": {"frames": 0}})");
  const std::string scene = (dir / "scene.json").string();
  // A folder of the user's: refused, and left as it was.
  fs::create_directories(dir / "mine");
  write(dir / "mine" / "notes.txt", "keep me");
  const auto mine = run("simulate " + scene + " --out " + (dir / "mine").string() + " --overwrite --quiet", true);
  INFO(mine.out);
  CHECK(mine.exit_code == 2);
  CHECK(mine.out.find("--overwrite replaces only a run folder this toolkit wrote") != std::string::npos);
  CHECK(fs::exists(dir / "mine" / "notes.txt"));
  // The current folder and the one above it: refused, whatever they hold. Run from a folder inside the test's own,
  // so that a guard that failed would empty only that.
  fs::create_directories(dir / "inner");
  write(dir / "inner" / "keep.txt", "keep me");
  for (const std::string& out : std::vector<std::string>{".", "..", "../inner", (dir / "inner").string()}) {
    const std::string command = "cd " + (dir / "inner").string() + " && " + NEEDLE_BINARY + " simulate " + scene + " --out " + out +
                                " --overwrite --quiet > " + (dir / "out.txt").string() + " 2>&1";
    const int status = std::system(command.c_str());
    std::ifstream text(dir / "out.txt");
    const std::string message((std::istreambuf_iterator<char>(text)), std::istreambuf_iterator<char>());
    INFO(out << ": " << message);
    CHECK(WEXITSTATUS(status) == 2);
    CHECK(message.find("--overwrite would replace") != std::string::npos);
    CHECK(fs::exists(dir / "inner" / "keep.txt"));
  }
  CHECK(fs::exists(dir / "scene.json"));
  CHECK(fs::exists(dir / "mine" / "notes.txt"));
  // A run folder: replaced, and marked as the toolkit's.
  const auto first = run("simulate " + scene + " --out " + (dir / "run").string() + " --quiet", true);
  REQUIRE(first.exit_code == 0);
  CHECK(fs::exists(dir / "run" / ".needle-run"));
  const auto again = run("simulate " + scene + " --out " + (dir / "run").string() + " --overwrite --quiet", true);
  INFO(again.out);
  CHECK(again.exit_code == 0);
  CHECK(fs::exists(dir / "run" / "summary.json"));
}

TEST_CASE("A number flag given NaN or infinity is refused before anything runs, whichever command", "[apps][sim][slow]") {
  // Options read NaN as "not given": without the check, --travel-mm nan quietly ran the default 30 mm.
  const fs::path dir = fresh_folder("non_finite");
  for (const std::string& args : std::vector<std::string>{"run --preset SB --travel-mm nan", "run --preset SB --tissue-E-MPa inf",
                                                           "run --preset SB --tissue-size-mm 40,-inf,2", "tip --preset SB --rod-length-mm NaN",
                                                           "tip --d-a nan", "stiffness --preset SB --free-length-mm 1e999", "mesh --preset SB --size-mm nan"}) {
    const auto r = run(args + " --out " + (dir / "out").string(), true);
    INFO(args << ": " << r.out);
    CHECK(r.exit_code == 2);
    CHECK(r.out.find("give a finite number") != std::string::npos);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
    CHECK(!fs::exists(dir / "out"));
  }
  // A finite but absurd travel: refused as well, before any work (1e9 mm started a run).
  const auto far = run("run --preset SB --travel-mm 1e9 --out " + (dir / "out").string(), true);
  CHECK(far.exit_code == 2);
  CHECK(far.out.find("travel 1000000000 mm is beyond any needle (at most 1000 mm)") != std::string::npos);
  CHECK(!fs::exists(dir / "out"));
}

TEST_CASE("Unknown flags, values that do not convert and negative counts get the project's one line and exit 2", "[apps][sim][slow]") {
  // CLI11's own words used to leak with its own exit codes; negative --threads and --frames quietly became the defaults.
  const fs::path dir = fresh_folder("cli_errors");
  for (const auto& [args, message] : std::vector<std::pair<std::string, std::string>>{
           {"run --preset SB --threads -1", "--threads: must be a whole number 0 or more (got -1)"},
           {"run --preset SB --frames 2.5", "--frames: must be a whole number 0 or more (got 2.5)"},
           {"simulate scene.json --threads -2", "--threads: must be a whole number 0 or more (got -2)"},
           {"run --preset SB --travel-mm abc", "--travel-mm abc: motion.travel_mm must be a number"},
           {"run --preset SB --d-a 0.1", "give one of --preset, --d-a or --recipe"},
           {"tip --preset SB --bogus-flag", "--bogus-flag"}}) {
    const auto r = run(args + " --out " + (dir / "out").string(), true);
    INFO(args << ": " << r.out);
    CHECK(r.exit_code == 2);
    CHECK(r.out.rfind("needle: error: ", 0) == 0);
    CHECK(r.out.find(message) != std::string::npos);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
    CHECK(!fs::exists(dir / "out"));
  }
  CHECK(run("run --help").exit_code == 0);
}

TEST_CASE("Ctrl-C during a run writes what there is, marked interrupted, exits 130 and leaves no scratch folder", "[apps][sim][slow]") {
  // The run (sb_quick: about 15 s) is sent SIGINT once its loop has written its first history rows.
  const fs::path dir = fresh_folder("interrupt");
  const fs::path out = dir / "run", partial = dir / ".run.partial" / "history.csv";
  const std::string command = fmt::format(
      "{} simulate {}/data/scenes/sb_quick.json --out {} --quiet 2>&1 & pid=$!; "
      "for i in $(seq 300); do [ -s {} ] && break; sleep 0.05; done; sleep 0.5; kill -INT $pid; wait $pid; echo \"exit $?\"",
      NEEDLE_BINARY, NEEDLE_SOURCE_DIR, out.string(), partial.string());
  const std::string text = shell(command).out;
  INFO(text);
  CHECK(text.find("needle: interrupted by SIGINT at t = ") != std::string::npos);
  CHECK(text.find("exit 130") != std::string::npos);
  REQUIRE(fs::exists(out / "summary.json"));
  std::ifstream summary_file(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  CHECK(summary["status"] == "interrupted");
  CHECK(summary["reason"].get<std::string>().rfind("interrupted by SIGINT at t = ", 0) == 0);
  CHECK(summary["time_ms"].get<double>() > 0);
  CHECK(summary["time_ms"].get<double>() < 4.125);
  CHECK(needle::read_csv_table((out / "history.csv").string()).rows.size() >= 2);
  for (const auto& entry : fs::directory_iterator(dir)) CHECK(entry.path().filename().string().find("partial") == std::string::npos);
}

TEST_CASE("Two writers on one run folder: the second is refused with the first's pid, and the first's run is complete", "[apps][sim][lock][slow]") {
  // The first run (sb_quick: about 15 s) is under way, writing its partial folder; the second, on the same --out, must
  // stop with one line and exit 2 without touching it (issue 51: it used to delete it, and the first lost its results).
  const fs::path dir = fresh_folder("two_writers");
  const fs::path out = dir / "run", partial = dir / ".run.partial" / "history.csv";
  const std::string command = fmt::format(
      "{0} simulate {1}/data/scenes/sb_quick.json --out {2} --quiet > {3}/first.log 2>&1 & pid=$!; "
      "for i in $(seq 600); do [ -s {4} ] && break; sleep 0.05; done; "
      "{0} simulate {1}/data/scenes/sb_quick.json --out {2} --quiet 2>&1; echo \"second exit $? first pid $pid\"; "
      "wait $pid; echo \"first exit $?\"",
      NEEDLE_BINARY, NEEDLE_SOURCE_DIR, out.string(), dir.string(), partial.string());
  const std::string text = shell(command).out;
  INFO(text);
  const auto pid_at = text.find("first pid ");
  REQUIRE(pid_at != std::string::npos);
  const std::string pid = text.substr(pid_at + 10, text.find('\n', pid_at) - pid_at - 10);
  CHECK(text.find("is being written by another needle (pid " + pid + ")") != std::string::npos);
  CHECK(text.find("second exit 2") != std::string::npos);
  CHECK(text.find("first exit 0") != std::string::npos);
  REQUIRE(fs::exists(out / "summary.json"));
  std::ifstream summary_file(out / "summary.json");
  CHECK(nlohmann::json::parse(summary_file)["status"] == "finished");
  for (const auto& entry : fs::directory_iterator(dir)) CHECK(entry.path().filename().string().find("partial") == std::string::npos);
  CHECK_FALSE(fs::exists(dir / ".run.lock"));
}
