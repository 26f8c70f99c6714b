// A run folder's scene.json is the effective scene its day's code wrote: the paper report reads stored runs through
// read_run_scene, where a key written only since its default changed stands, when absent, for the model before.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "runs/scene.h"
#include "runs/scene_key_spellings.h"
#include "studies/run_model_description.h"

namespace fs = std::filesystem;
using needle::Scene;

namespace {

fs::path scene_file(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / "needle_test_run_scene";
  fs::create_directories(dir);
  const fs::path path = dir / (name + ".json");
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("A stored run's scene without the keys written since reads as the model before them, a scene file as today's defaults",
          "[scene]") {
  // Before the needle cut and the lip's modes: neither key.
  const fs::path old = scene_file("before_cut", R"({"needle": {"preset": "AMB"}, "tissue": {"enabled": true, "contact": {"skin_mm": 0.02}}})");
  const Scene run = needle::read_run_scene(old.string());
  CHECK_FALSE(run.tissue.separation.needle_cut);
  CHECK(run.tissue.separation.lip.mode == needle::LipReleaseMode::off);
  const Scene file = needle::read_scene(old.string());
  CHECK(file.tissue.separation.needle_cut);
  CHECK(file.tissue.separation.lip.mode == needle::LipReleaseMode::crushed);
  CHECK(file.tissue.separation.lip.depth_mm == needle::kSceneCrushedLipDepthMm);
  CHECK(needle::describe_run_model(run, 1).find("the needle does not cut the bonds") != std::string::npos);
  CHECK(needle::describe_run_model(run, 1).find("the lip below the tip point stays as the tissue is (no lip release)") != std::string::npos);
  CHECK(needle::describe_run_model(file, 1).find("lip") == std::string::npos);  // the default goes unnamed

  // 2026-11-27: a crushed lip, its depth not yet written (the whole lip then).
  const fs::path crushed = scene_file("crushed_whole", R"({"tissue": {"contact": {"cuts_bonds": true, "lip_release_mode": "crushed"}}})");
  const Scene whole = needle::read_run_scene(crushed.string());
  CHECK(whole.tissue.separation.needle_cut);
  CHECK(whole.tissue.separation.lip.whole_lip());
  CHECK(needle::describe_run_model(whole, 1).find("the whole lip below the tip point is crushed (lip release)") != std::string::npos);
  CHECK(needle::read_scene(crushed.string()).tissue.separation.lip.depth_mm == needle::kSceneCrushedLipDepthMm);

  // Today's effective scene says every key, and reads the same both ways.
  const Scene today = needle::read_scene(old.string());
  const fs::path written = scene_file("today", needle::scene_to_json(today).dump(2));
  CHECK(needle::scene_to_json(needle::read_run_scene(written.string())) == needle::scene_to_json(today));
}

TEST_CASE("Every run scene stored under docs/ reads through read_run_scene, and its effective scene reads back the same", "[scene][slow]") {
  int scenes = 0;
  for (const auto& entry : fs::recursive_directory_iterator(fs::path(NEEDLE_SOURCE_DIR) / "docs")) {
    if (entry.path().filename() != "scene.json") continue;
    ++scenes;
    INFO(entry.path().string());
    Scene stored;
    REQUIRE_NOTHROW(stored = needle::read_run_scene(entry.path().string()));
    const nlohmann::json effective = needle::scene_to_json(stored);
    const fs::path again = scene_file("again", effective.dump(2));
    CHECK(needle::scene_to_json(needle::read_run_scene(again.string())) == effective);
  }
  CHECK(scenes > 100);  // the sensitivity studies' cases and the stored benches
}

TEST_CASE("The separation's and cutting's keys in their older spelling (tissue.contact.crack_reach_mm) read as their sections' keys, with a note",
          "[scene]") {
  const Scene today = needle::parse_scene(
      R"({"tissue": {"separation": {"needle_cut": false, "slit": {"half_height_mm": 0.5, "lead_mm": 0.1},
                                    "crack": {"reach_mm": 1, "angles_deg": [0, -45], "lead": "0.2 mm"},
                                    "lip": {"mode": "free", "below_mm": 0.1, "depth_mm": 0.3}},
                     "cutting": {"pressure_MPa": 0.1}}})",
      "today.json");
  const Scene older = needle::parse_scene(
      R"({"tissue": {"contact": {"cuts_bonds": false, "slit_half_height_mm": 0.5, "slit_lead_mm": 0.1,
                                 "crack_reach_mm": 1, "crack_angles_deg": [0, -45], "crack_lead": "0.2 mm",
                                 "lip_release_mode": "free", "lip_release_below_mm": 0.1, "lip_release_depth_mm": 0.3,
                                 "cutting_pressure_MPa": 0.1}}})",
      "older.json");
  CHECK(needle::scene_to_json(older) == needle::scene_to_json(today));
  CHECK(today.notes.empty());
  REQUIRE(older.notes.size() == 10);  // one a key, each naming the file, the line and where the key lives now
  CHECK(older.notes[0].rfind("older.json:", 0) == 0);
  bool crack_note = false;
  for (const std::string& note : older.notes)
    crack_note |= note.find("tissue.contact.crack_reach_mm is read as tissue.separation.crack.reach_mm") != std::string::npos;
  CHECK(crack_note);
  CHECK_FALSE(today.tissue.separation.needle_cut);
  CHECK(today.tissue.separation.crack.lead_mm == Approx(0.2));
  CHECK(today.tissue.cutting.pressure_MPa == 0.1);

  // Both spellings of one key: refused, naming both.
  CHECK_THROWS_WITH(needle::parse_scene(R"({"tissue": {"contact": {"crack_reach": "1 mm"}, "separation": {"crack": {"reach_mm": 2}}}})", "both.json"),
                    Catch::Contains("tissue.separation.crack.reach_mm or tissue.contact.crack_reach (its older spelling), not both"));
  // The checks read where the key is given: a slit needs a half model, a crack's shape a crack.
  CHECK_THROWS_WITH(needle::parse_scene(R"({"needle": {"half_model": false}, "tissue": {"contact": {"slit_half_height_mm": 0.5}}})", "full.json"),
                    Catch::Contains("tissue.contact.slit_half_height_mm: the slit opens the symmetry plane"));
  CHECK_THROWS_WITH(needle::parse_scene(R"({"tissue": {"separation": {"crack": {"lead_mm": 0.5}}}})", "shape.json"),
                    Catch::Contains("tissue.separation.crack.lead_mm: the crack's shape (its angles and lead) needs a crack"));

  // --set in the older spelling sets today's key (and replaces its value), with a note naming the setting.
  const Scene set = needle::apply_scene_settings(today, {"tissue.contact.crack_reach_mm=1.5", "tissue.contact.cuts_bonds=true"});
  CHECK(set.tissue.separation.crack.reach_mm == 1.5);
  CHECK(set.tissue.separation.needle_cut);
  REQUIRE(set.notes.size() == 2);
  CHECK(set.notes[0] == "--set tissue.contact.crack_reach_mm=1.5: tissue.contact.crack_reach_mm is read as tissue.separation.crack.reach_mm "
                        "(its place since 2026-11-28; docs/scenes.md)");
  CHECK(needle::current_scene_key("tissue.contact.lip_release_depth") == "tissue.separation.lip.depth");
  CHECK(needle::current_scene_key("tissue.contact.skin_mm") == "tissue.contact.skin_mm");
  CHECK(needle::current_scene_key("tissue.contact.crack_angles_deg") == "tissue.separation.crack.angles_deg");
}
