// `needle run --fire-cannula` (issue 50): after a short insertion the cannula is fired over SB's groove, and the run
// reports the sample it encloses. The run goes to the stroke's end, the deflection is the insertion's (the same as the
// run without the firing, whose files say nothing of a firing), the sample lies within the groove's part in the tissue,
// the frames mark the particles in the cannula, and a firing that cannot take tissue is refused before any folder exists.
#include <catch2/catch.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "runs/csv_table.h"
#include "cli_run.h"
#include "run_fixtures.h"

namespace fs = std::filesystem;
using namespace needle_test;

namespace {

// SB (26 mm, T4 0.5 mm) pushed 4.2 mm into a 5 mm block: its groove's front wall, 3 mm behind tip point A, ends 1.2 mm
// inside the tissue.
fs::path sb_scene(const std::string& name) {
  const fs::path dir = fresh_folder(name);
  write(dir / "scene.json", R"({"needle": {"preset": "SB", "length_mm": 26, "mesh": {"order": 1, "size_mm": 0.5}},)"
                            R"("motion": {"accel_time_ms": 0.02, "travel_mm": 4.2}, "cannula": {"enabled": false},)"
                            R"("tissue": {"size_mm": [5, 2.4, 1.2], "spacing_mm": 0.4}, "solver": {"mass_scaling_dt_ms": 1e-5},)"
                            R"("output": {"frames": 2, "history_interval_ms": 0.02}})");
  return dir;
}

RunFiles read_run(const fs::path& folder) {
  std::ifstream scene_file(folder / "scene.json"), summary_file(folder / "summary.json");
  return {nlohmann::json::parse(scene_file), nlohmann::json::parse(summary_file), needle::read_csv_table((folder / "history.csv").string())};
}

}  // namespace

TEST_CASE("needle run --fire-cannula takes a sample from the groove after the insertion", "[apps][lspg][gmsh][cannula][slow]") {
  const fs::path dir = sb_scene("fire_cannula");
  const std::string scene = (dir / "scene.json").string();
  const Result fired = run("run --scene " + scene + " --fire-cannula --out " + (dir / "fired").string() + " --quiet", true);
  INFO(fired.out);
  REQUIRE(fired.exit_code == 0);
  const Result plain = run("run --scene " + scene + " --out " + (dir / "plain").string() + " --quiet", true);
  REQUIRE(plain.exit_code == 0);
  const RunFiles f = read_run(dir / "fired"), p = read_run(dir / "plain");

  // The scene says so; without the flag nothing is written of a firing.
  CHECK(f.scene["cannula"]["firing"]["enabled"] == true);
  CHECK(f.scene["cannula"]["firing"]["speed_m_per_s"] == 4.0);
  CHECK_FALSE(f.scene["cannula"]["firing"].contains("throw_mm"));  // to the groove's far end
  CHECK_FALSE(p.scene["cannula"].contains("firing"));
  CHECK_FALSE(p.summary.contains("sample"));
  CHECK(f.summary["status"] == "finished");

  // The stroke: from the cannula's front at rest (the entry face, 4.2 mm behind A after the travel) to the groove's
  // front wall (3 mm behind A) at 4 m/s, after the insertion; the run ends with it.
  const nlohmann::json& sample = f.summary["sample"];
  const nlohmann::json& cannula = sample["cannula"];
  CHECK(cannula["start_x_mm"].get<double>() == Approx(-4.2));
  CHECK(cannula["stop_x_mm"].get<double>() == Approx(-3.0).margin(0.01));
  CHECK(cannula["front_x_mm_at_end"].get<double>() == Approx(cannula["stop_x_mm"].get<double>()));
  const double insertion_end_ms = p.summary["time_ms"].get<double>();
  CHECK(cannula["start_time_ms"].get<double>() == Approx(insertion_end_ms));
  const double stroke_ms = (cannula["stop_x_mm"].get<double>() - cannula["start_x_mm"].get<double>()) / 4.0;
  CHECK(f.summary["time_ms"].get<double>() == Approx(insertion_end_ms + stroke_ms));
  CHECK(f.history.column("cannula_front_x_mm").back() == Approx(cannula["stop_x_mm"].get<double>()));

  // The deflection is the insertion's: the run without the firing's, and the history's at the insertion's end (the needle
  // is held still from then on).
  INFO("deflection fired " << f.summary["deflection_mm"] << ", plain " << p.summary["deflection_mm"]);
  CHECK(f.summary["deflection_mm"].get<double>() == Approx(p.summary["deflection_mm"].get<double>()).epsilon(1e-6));
  CHECK(f.summary["needle_held"]["from_ms"].get<double>() == Approx(insertion_end_ms));
  // A row at the insertion's end, once, as the plain run ends on one: the instant the deflection is read (the paper
  // report's loads and curves stop there), then the stroke's rows.
  const std::vector<double> fired_t = f.history.column("time_ms"), plain_t = p.history.column("time_ms");
  const auto at_end = std::find(fired_t.begin(), fired_t.end(), plain_t.back());
  REQUIRE(at_end != fired_t.end());
  CHECK(std::count(fired_t.begin(), fired_t.end(), plain_t.back()) == 1);
  CHECK(fired_t.back() > plain_t.back());
  const size_t row = static_cast<size_t>(at_end - fired_t.begin());
  CHECK(f.history.column("deflection_mm")[row] == Approx(p.history.column("deflection_mm").back()).epsilon(1e-6));
  CHECK(f.history.column("insertion_mm")[row] == Approx(p.history.column("insertion_mm").back()));
  for (const char* force : {"contact_force_y_N", "drive_force_y_N"}) {
    INFO(force);
    CHECK(f.history.column(force)[row] == Approx(p.history.column(force).back()).epsilon(1e-6).margin(1e-12));
  }

  // The sample: tissue in the groove's part inside the block (1.2 mm), I_s within its extent, its mass its
  // volume's at the card's density.
  const double length = sample["length_mm"].get<double>(), I_s = sample["I_s_mm"].get<double>();
  CHECK(sample["particles"].get<long>() > 0);
  CHECK(length > 0);
  CHECK(length <= 1.2 + 0.2 + 1e-9);  // the groove's part in the tissue, and a particle's half spacing beyond the entry face
  CHECK(I_s > 0);
  // I_s is the floor the nearest layer covers: within that layer's extent, within the whole sample's; the contact's list
  // is kept beside it, its covered length within its extent.
  CHECK(sample["I_s_measure"] == "floor_layer_covered_mm");
  CHECK(I_s == sample["floor_layer_covered_mm"].get<double>());
  CHECK(I_s <= sample["floor_layer_length_mm"].get<double>() + 1e-12);
  CHECK(sample["floor_layer_length_mm"].get<double>() <= length + 1e-12);
  CHECK(sample["floor_covered_mm"].get<double>() <= sample["floor_length_mm"].get<double>() + 1e-12);
  CHECK(sample["floor_length_mm"].get<double>() <= length + 1e-12);
  CHECK(sample["mass_g"].get<double>() == Approx(0.98e-3 * sample["volume_mm3"].get<double>()));
  CHECK(f.summary["cannula_edge"]["bonds_cut"].get<long>() > 0);

  // The last frame marks the particles in the cannula.
  std::ifstream frame(dir / "fired" / "frames" / "tissue_0002.vtp");
  REQUIRE(frame.good());
  const std::string head((std::istreambuf_iterator<char>(frame)), std::istreambuf_iterator<char>());
  CHECK(head.find("Name=\"in_cannula\"") != std::string::npos);
}

TEST_CASE("needle run --fire-cannula refuses a firing that can take no tissue, before any folder exists", "[apps][cannula]") {
  const fs::path dir = sb_scene("fire_cannula_refused");
  const std::string scene = (dir / "scene.json").string();
  // With the cannula's front at rest 30 mm behind the entry face, a 1 mm throw stops it 8.2 mm behind the groove.
  const Result short_throw =
      run("run --scene " + scene + " --fire-cannula --firing-throw-mm 1 --set cannula.front_x_mm=-30 --out " + (dir / "run").string(), true);
  INFO(short_throw.out);
  CHECK(short_throw.exit_code == 2);
  CHECK(short_throw.out.find("behind the groove's back wall") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "run"));
  // A plain rod has no groove to take tissue from.
  refused_in_one_line("fire_cannula_rod", "--fire-cannula", "needs a needle with one");
  // A speed must be a speed.
  refused_in_one_line("fire_cannula_speed", "--fire-cannula --firing-speed-m-per-s 0", "cannula.firing.speed");
}
