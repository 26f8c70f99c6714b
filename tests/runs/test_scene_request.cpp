// One path from a command to a scene (runs/scene_request.h): the tissue's E and where it came from, for every way a
// command can ask, against the calibration files themselves and the scene reader.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "runs/insertion_run.h"
#include "runs/run_defaults.h"
#include "runs/model_levels.h"
#include "runs/scene_request.h"

namespace fs = std::filesystem;
using needle::NamedSceneSetting;
using needle::SceneRequest;

namespace {

double E_in(const std::string& calibration) {
  std::ifstream in(calibration);
  return nlohmann::json::parse(in)["tissue_E_MPa"].get<double>();
}

}  // namespace

TEST_CASE("A request's tissue is calibrated on SB for the model level its scene ends up at, unless E is given", "[runs][scene]") {
  const std::string fast = needle::default_calibration_file("fast");
  const std::string full = needle::default_calibration_file("full");
  CHECK(fs::path(fast).filename() == "calibration_sb.json");
  CHECK(fs::path(full).filename() == "calibration_sb_full.json");
  REQUIRE(E_in(fast) != E_in(full));

  SceneRequest plain;
  plain.preset = "AMB";
  const needle::ResolvedScene a = needle::resolve_scene(plain);
  CHECK(a.scene.tissue.enabled);
  CHECK(a.scene.needle.preset == "AMB");
  CHECK(a.scene.tissue.material.E_MPa == E_in(fast));
  CHECK(a.calibration_file == fast);
  CHECK(a.E_source.find("calibrated on SB: " + fast) == 0);

  // A setting that changes the model level (here the full level's keys, one by one) takes that level's calibration:
  // the level is judged after the settings, as a sweep's "set" keys and a run's --set give it.
  SceneRequest by_keys = plain;
  by_keys.settings = {{"needle.model=fe", "needle.model=fe"},
                      {"tissue.contact.law=penalty", "tissue.contact.law=penalty"},
                      {"solver.tissue_mass_scaling=false", "solver.tissue_mass_scaling=false"},
                      {"solver.tissue_mass_scaling_dt_ms=0", "solver.tissue_mass_scaling_dt_ms=0"},
                      {"tissue.spg.support=sphere", "tissue.spg.support=sphere"},
                      {"solver.tissue_rate_levels=0", "solver.tissue_rate_levels=0"}};
  const needle::ResolvedScene k = needle::resolve_scene(by_keys);
  CHECK(needle::model_level_of(k.scene) == "full");
  CHECK(k.scene.tissue.material.E_MPa == E_in(full));
  CHECK(k.calibration_file == full);
  SceneRequest by_level = plain;
  by_level.model = "full";
  CHECK(needle::resolve_scene(by_level).scene.tissue.material.E_MPa == E_in(full));

  // Given E, a calibration file, or E set last: each wins and says so.
  SceneRequest given = plain;
  given.tissue_E_MPa = 0.123;
  const needle::ResolvedScene g = needle::resolve_scene(given);
  CHECK(g.scene.tissue.material.E_MPa == 0.123);
  CHECK(g.E_source == "given with --tissue-E-MPa");
  CHECK(g.calibration_file.empty());
  SceneRequest from_file = plain;
  from_file.calibration_file = full;
  CHECK(needle::resolve_scene(from_file).scene.tissue.material.E_MPa == E_in(full));
  SceneRequest set_last = from_file;
  set_last.settings = {{"tissue.material.E_MPa=0.2", "--set tissue.material.E_MPa=0.2"}};
  const needle::ResolvedScene s = needle::resolve_scene(set_last);
  CHECK(s.scene.tissue.material.E_MPa == 0.2);
  CHECK(s.E_source == "given with --set tissue.material.E_MPa=0.2");
  CHECK(s.calibration_file.empty());

  // The card, where a command starts from it (calibrate), and a scene file's own E.
  SceneRequest card = plain;
  card.card_by_default = true;
  const needle::ResolvedScene c = needle::resolve_scene(card);
  CHECK(c.scene.tissue.material.E_MPa == needle::TissueMaterial{}.E_MPa);
  CHECK(c.E_source.find("the card's") == 0);
  const fs::path file = fs::temp_directory_path() / "needle_scene_request.json";
  std::ofstream(file) << R"({"needle": {"preset": "LMB"}, "tissue": {"material": {"E_MPa": 0.0777}}, "motion": {"travel_mm": 5}})";
  SceneRequest scene_file;
  scene_file.scene_file = file.string();
  const needle::ResolvedScene f = needle::resolve_scene(scene_file);
  CHECK(f.scene.tissue.material.E_MPa == 0.0777);
  CHECK(f.scene.needle.preset == "LMB");
  CHECK(f.E_source == "from the scene " + file.string());

  // Requests that contradict themselves.
  SceneRequest both = plain;
  both.tissue_E_MPa = 0.1;
  both.calibration_file = fast;
  CHECK_THROWS_WITH(needle::resolve_scene(both), Catch::Contains("give --tissue-E-MPa or --calibration, not both"));
  SceneRequest two = plain;
  two.d_a_mm = 0.1;
  CHECK_THROWS_WITH(needle::resolve_scene(two), Catch::Contains("give one of --preset, --d-a or --recipe"));
  SceneRequest bad = plain;
  bad.settings = {{"tissue.friction=7", "--tissue-friction 7"}, {"motion.travel_mm=20", "--travel-mm 20"}};
  CHECK_THROWS_WITH(needle::resolve_scene(bad), Catch::StartsWith("--tissue-friction 7: tissue.friction must lie in [0, 2]"));
}
