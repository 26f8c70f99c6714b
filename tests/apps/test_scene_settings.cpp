// --set KEY=VALUE: any scene key set on the command line through the scene reader (apps/scene.h), and the
// calibrated tissue that `needle run` takes by default.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>

#include "runs/run_defaults.h"
#include "runs/scene.h"
#include "cli_run.h"
#include "core/input_error.h"
#include "run_fixtures.h"

namespace fs = std::filesystem;
using namespace needle_test;

TEST_CASE("apply_scene_settings sets dotted keys with units, replaces a key's other form and the needle's source, and names --set in errors",
          "[apps][scene]") {
  const needle::Scene base = needle::parse_scene("{}", "(test)");
  const needle::Scene set = needle::apply_scene_settings(
      base, {"tissue.material.nu=0.49", "motion.travel=3 cm", "tissue.size_mm=[20, 8, 4]", "needle.d_a_mm=0.1", "tissue.material.law=stiffening_elastic"});
  CHECK(set.tissue.material.nu == 0.49);
  CHECK(set.motion.travel_mm == Approx(30.0).epsilon(1e-12));  // "3 cm" through the reader's units, replacing travel_mm
  CHECK(set.tissue.size_mm == Eigen::Vector3d(20, 8, 4));
  CHECK(set.needle.d_a_mm == 0.1);
  CHECK(set.needle.preset.empty());  // one needle source replaces the other
  CHECK(set.tissue.material.law == needle::TissueLaw::stiffening_elastic);
  CHECK(set.source == base.source);
  // Everything not set is the scene's own: the effective scenes differ in the set keys only.
  nlohmann::json a = needle::scene_to_json(base), b = needle::scene_to_json(set);
  for (nlohmann::json* j : {&a, &b}) {
    (*j)["tissue"]["material"].erase("nu");
    (*j)["tissue"]["material"].erase("law");
    (*j)["motion"].erase("travel_mm");
    (*j)["tissue"].erase("size_mm");
    (*j)["needle"].erase("preset");
    (*j)["needle"].erase("d_a_mm");
  }
  CHECK(a == b);
  CHECK(needle::scene_to_json(needle::apply_scene_settings(base, {})) == needle::scene_to_json(base));

  auto refusal = [&](const std::string& setting) {
    try {
      needle::apply_scene_settings(base, {setting});
    } catch (const needle::InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK(refusal("motion.travle_mm=3") == "--set motion.travle_mm=3: motion.travle_mm: unknown key (misspelt, or without its unit suffix?)");
  CHECK(refusal("motion.travel=3").find("--set motion.travel=3: motion.travel") == 0);  // a bare number where a unit is needed
  CHECK(refusal("tissue.material.nu=0.7").find("--set tissue.material.nu=0.7: tissue nu must lie in (-1, 0.5) (got 0.7)") == 0);
  CHECK(refusal("tissue.material.E_MPa") == "--set tissue.material.E_MPa: give key=value, e.g. --set tissue.material.E_MPa=0.1");
  // Physical ranges (issue 51): an absurd friction or drive speed is refused by the key that has it, not run or blamed elsewhere.
  CHECK(refusal("tissue.friction=1e308").find("tissue.friction") != std::string::npos);
  CHECK(refusal("tissue.friction=1e308").find("must lie in [0, 2]") != std::string::npos);
  CHECK(refusal("cannula.friction=3").find("must lie in [0, 2]") != std::string::npos);
  CHECK(refusal("motion.speed_m_per_s=1e308").find("motion.speed") != std::string::npos);
  CHECK(refusal("motion.speed_m_per_s=1e308").find("at most 100 m/s") != std::string::npos);
  CHECK(refusal("motion.speed_m_per_s=4") == "accepted");
  CHECK(refusal("tissue.friction=0.4") == "accepted");
  CHECK(refusal("tissue..nu=1").find("is not a dotted scene key") != std::string::npos);
  CHECK(refusal("needle.length_mm.x=1").find("length_mm is a value, not a section") != std::string::npos);
}

TEST_CASE("A --set setting touches only its own key and that key's unit spellings: every key next to a longer key of the same prefix keeps its neighbour",
          "[apps][scene]") {
  // Every optional key written, so that every pair of keys the effective scene can hold is here.
  const needle::Scene base = needle::parse_scene(
      R"({"tissue": {"enabled": true, "spg": {"stabilization_coefficient": 0.3, "kernel_update_interval_steps": 25},
                     "material": {"relaxing_shear_fraction": 0.5, "relaxation_time_ms": 0.2},
                     "separation": {"slit": {"half_height_mm": 0.5}, "crack": {"reach_mm": 1}}, "cutting": {"pressure_MPa": 0.1}},
          "solver": {"tissue_mass_scaling": true, "tissue_mass_scaling_dt_ms": 0.003}})",
      "(test)");
  // The longer key's value above, which a default would not give back.
  const std::map<std::string, nlohmann::json> neighbour_value = {
      {"stabilization_coefficient", 0.3}, {"kernel_update_interval_steps", 25}, {"tissue_mass_scaling_dt_ms", 0.003}};
  int pairs = 0;
  std::function<void(const nlohmann::json&, const std::string&)> walk = [&](const nlohmann::json& section, const std::string& path) {
    for (const auto& [key, value] : section.items()) {
      if (value.is_object()) {
        walk(value, path + key + ".");
        continue;
      }
      for (const auto& [longer, longer_value] : section.items()) {
        if (longer_value.is_object() || longer.rfind(key + "_", 0) != 0) continue;
        // `key` and `longer` are two settings (no unit suffix turns one into the other, e.g. stabilization and
        // stabilization_coefficient): setting the first to its own value must leave the second as it was.
        INFO(path + key + " next to " + path + longer);
        REQUIRE(neighbour_value.count(longer));  // a new pair: give the longer key a value other than its default above
        ++pairs;
        const needle::Scene set = needle::apply_scene_settings(base, {path + key + "=" + (value.is_string() ? value.get<std::string>() : value.dump())});
        // Set to its own value, the key changes nothing: an erased neighbour would fall back to its default.
        CHECK(needle::scene_to_json(set) == needle::scene_to_json(base));
      }
    }
  };
  walk(needle::scene_to_json(base), "");
  CHECK(pairs == 3);
  // A unit spelling still replaces the other: travel after travel_mm, E after E_MPa.
  const needle::Scene travel = needle::apply_scene_settings(base, {"motion.travel=2 cm"});
  CHECK(travel.motion.travel_mm == Approx(20.0).epsilon(1e-12));
}

TEST_CASE("needle run --set and needle simulate --set change the run's scene, a bad key is refused with nothing written", "[apps][lspg][gmsh][slow]") {
  const RunFiles set = run_rod_into_small_block("set_nu", "--set tissue.material.nu=0.4 --set tissue.friction=0.3");
  CHECK(set.scene["tissue"]["material"]["nu"].get<double>() == 0.4);
  CHECK(set.scene["tissue"]["friction"].get<double>() == 0.3);
  CHECK(set.summary["status"] == "finished");
  refused_on_small_block("set_bad", "--set tissue.material.nuu=0.4", "--set tissue.material.nuu=0.4: unknown key 'material.nuu'");

  const fs::path dir = fresh_folder("simulate_set");
  write(dir / "scene.json", R"({"needle": {"plain_rod": true, "length_mm": 6, "mesh": {"order": 1, "size_mm": 0.5}},)"
                            R"("motion": {"accel_time_ms": 0.02, "travel_mm": 0.2}, "cannula": {"enabled": false}, "output": {"frames": 0}})");
  const auto r = run("simulate " + (dir / "scene.json").string() + " --set motion.travel_mm=0.3 --out " + (dir / "run").string() + " --quiet", true);
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  std::ifstream summary_file(dir / "run" / "summary.json");
  CHECK(nlohmann::json::parse(summary_file)["insertion_mm"].get<double>() == Approx(0.3).epsilon(1e-9));
}

TEST_CASE("needle run with no E given takes the shipped SB calibration of its model level and says so", "[apps][lspg][gmsh][slow]") {
  // The run defaults, shrunk with --set to seconds: a short T4 SB, a small block, 0.8 mm.
  const fs::path dir = fresh_folder("calibrated_default");
  const std::string shrink =
      " --set needle.length_mm=26 --set needle.mesh.order=1 --set needle.mesh.size_mm=0.5 --set cannula.enabled=false"
      " --set motion.accel_time_ms=0.02 --set motion.travel_mm=0.8 --set tissue.size_mm=[2,2.4,1.2] --set tissue.path_refinement=1"
      " --set solver.mass_scaling_dt_ms=1e-5 --frames 0";
  const auto r = run("run --preset SB --out " + (dir / "run").string() + shrink, true);
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  std::ifstream calibration(fs::path(NEEDLE_SOURCE_DIR) / "data/paper/calibration_sb.json"), scene(dir / "run" / "scene.json");
  const double calibrated_E = nlohmann::json::parse(calibration)["tissue_E_MPa"].get<double>();
  CHECK(nlohmann::json::parse(scene)["tissue"]["material"]["E_MPa"].get<double>() == calibrated_E);
  CHECK(r.out.find("calibrated on SB: ") != std::string::npos);
  CHECK(r.out.find("data/paper/calibration_sb.json") != std::string::npos);
  std::ifstream default_scene(dir / "run" / "scene.json");
  const nlohmann::json run_scene = nlohmann::json::parse(default_scene);
  CHECK(run_scene["needle"]["model"] == "implicit");  // the run defaults are the fast level
  CHECK(run_scene["tissue"]["spg"]["support"] == "ellipsoid");

  // The full model takes the full model's own calibration (another E), the fast level by name the default's.
  const auto full = run("run --preset SB --model full --out " + (dir / "full").string() + shrink, true);
  INFO(full.out);
  REQUIRE(full.exit_code == 0);
  std::ifstream full_calibration(fs::path(NEEDLE_SOURCE_DIR) / "data/paper/calibration_sb_full.json"), full_scene(dir / "full" / "scene.json");
  const double full_E = nlohmann::json::parse(full_calibration)["tissue_E_MPa"].get<double>();
  CHECK(full_E != calibrated_E);
  const nlohmann::json full_run_scene = nlohmann::json::parse(full_scene);
  CHECK(full_run_scene["tissue"]["material"]["E_MPa"].get<double>() == full_E);
  CHECK(full_run_scene["needle"].value("model", std::string("fe")) == "fe");  // the FE needle is written by leaving the key out
  CHECK(full_run_scene["tissue"]["spg"]["support"] == "sphere");
  CHECK(full.out.find("data/paper/calibration_sb_full.json") != std::string::npos);

  // --tissue-E-MPa and --set override it, and say so.
  const auto given = run("run --preset SB --tissue-E-MPa 0.2 --out " + (dir / "given").string() + shrink, true);
  CHECK(given.out.find("tissue E 0.2 MPa, given with --tissue-E-MPa") != std::string::npos);
  const auto set = run("run --preset SB --set tissue.material.E_MPa=0.3 --out " + (dir / "set").string() + shrink, true);
  CHECK(set.out.find("tissue E 0.3 MPa, given with --set") != std::string::npos);
}
