// `needle calibrate` over run folders written here with known deflections: every E it asks for is already
// there, so it runs nothing. A run of the same scene at another E, already in OUT/runs, gives the slope
// d delta / d E without a sensitivity run, whatever threads it ran on; a run of another scene there is passed over.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <nlohmann/json.hpp>

#include "runs/insertion_run.h"
#include "runs/run_defaults.h"
#include "runs/scene_request.h"
#include "apps/scene_overrides.h"
#include "runs/scene.h"
#include "cli_run.h"

namespace fs = std::filesystem;
using json = nlohmann::json;
using needle_test::run;

namespace {

// A run folder as `needle calibrate` names and writes it: the scene at E (run on `threads` worker threads) and a
// finished summary.
void write_run_at(const fs::path& runs, const needle::Scene& base, double E_MPa, double deflection_mm, int threads = 0) {
  needle::Scene scene = base;
  scene.tissue.material.E_MPa = E_MPa;
  scene.solver.threads = threads;
  const fs::path folder = runs / fmt::format("E_{:.6g}MPa", E_MPa);
  fs::create_directories(folder);
  std::ofstream(folder / "scene.json") << needle::scene_to_json(scene).dump(2);
  std::ofstream(folder / "summary.json") << json{{"status", "finished"}, {"deflection_mm", deflection_mm}, {"insertion_mm", 4.0},
                                                 {"runtime_s", 60.0}}
                                                .dump(2);
}

needle::Scene calibration_scene(double skin_mm) {
  // What `calibrate --preset SB --travel-mm 4 --contact-skin-mm <skin>` runs (the short travel keeps a run cheap
  // should the test ever make one).
  needle::SceneOverrides overrides;
  overrides.give("--travel-mm", {"4"});
  overrides.give("--contact-skin-mm", {fmt::format("{}", skin_mm)});
  needle::SceneRequest request;  // as calibrate_command.cpp asks for it
  request.preset = "SB";
  request.card_by_default = true;
  request.settings = needle::scene_override_settings(overrides);
  return needle::resolve_scene(request).scene;
}

}  // namespace

TEST_CASE("needle calibrate takes the slope from a run of the same scene already in OUT/runs instead of making one",
          "[apps][calibrate]") {
  const fs::path dir = fs::temp_directory_path() / "needle_calibrate_reuse";
  fs::remove_all(dir);
  const fs::path runs = dir / "runs";
  write_run_at(runs, calibration_scene(0.02), 0.080, -1.115);   // the start: within 0.05 of the target
  write_run_at(runs, calibration_scene(0.02), 0.0748, -1.042, 2);  // an earlier run of the same scene, on two threads
  write_run_at(runs, calibration_scene(0.04), 0.078, -2.0);     // nearer in E, but another contact: not a partner
  const auto result = run(fmt::format("calibrate --preset SB --target-deflection-mm -1.14 --start-E-MPa 0.08 --travel-mm 4 "
                                      "--contact-skin-mm 0.02 --out {}",
                                      dir.string()),
                          true);
  INFO(result.out);
  REQUIRE(result.exit_code == 0);
  CHECK(result.out.find("E = 0.08 MPa: reused") != std::string::npos);
  CHECK(result.out.find("E = 0.0748 MPa: already there") != std::string::npos);
  CHECK(!fs::exists(runs / "E_0.096MPa"));  // no sensitivity run
  std::ifstream file(dir / "calibration.json");
  const json c = json::parse(file);
  CHECK(c["converged"] == true);
  CHECK(c["tissue_E_MPa"].get<double>() == Approx(0.080));
  CHECK(c["deflection_mm"].get<double>() == Approx(-1.115));
  const double slope = (-1.115 - -1.042) / (0.080 - 0.0748);
  CHECK(c["sensitivity_mm_per_MPa"].get<double>() == Approx(slope));
  CHECK(c["relative_sensitivity"].get<double>() == Approx(slope * 0.080 / -1.115));
  CHECK(c["sensitivity_from_E_MPa"] == json::array({0.080, 0.0748}));
  REQUIRE(c["runs"].size() == 2);  // the run of the other scene is not listed
  CHECK(c["runs"][1]["run_folder"] == "runs/E_0.0748MPa");
}

TEST_CASE("needle calibrate refuses to fire the cannula, which changes nothing it reads, before it writes anything", "[apps][calibrate]") {
  const fs::path dir = fs::temp_directory_path() / "needle_calibrate_fired";
  fs::remove_all(dir);
  const auto result = run(fmt::format("calibrate --preset SB --target-deflection-mm -1.14 --travel-mm 4 --fire-cannula --out {}", dir.string()), true);
  INFO(result.out);
  CHECK(result.exit_code == 2);
  CHECK(result.out.find("drop --fire-cannula") != std::string::npos);
  CHECK(!fs::exists(dir));
}
