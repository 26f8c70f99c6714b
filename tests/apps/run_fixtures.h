#pragma once
// The small coupled runs the CLI tests make: a plain rod or a short SB pushed 0.8 mm into a small tissue block
// by `needle run --scene`, the run folder's files read back, and refused runs checked (tests only).
#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "runs/csv_table.h"
#include "runs/scene.h"
#include "cli_run.h"
#include "core/input_error.h"

namespace needle_test {

namespace fs = std::filesystem;


inline fs::path fresh_folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("needle_sim_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

inline void write(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// A plain rod (6 mm, T4 0.5 mm, no cannula) pushed travel_mm into the tissue block `tissue` (JSON) by
// `needle run --scene`; the run goes to dir/run. The exit code and output of the command.
inline Result run_rod_into_block(const fs::path& dir, const std::string& tissue, double travel_mm, int frames,
                                       const std::string& flags = "") {
  write(dir / "scene.json", R"({"needle": {"plain_rod": true, "length_mm": 6, "mesh": {"order": 1, "size_mm": 0.5}},)"
                                R"("motion": {"accel_time_ms": 0.02, "travel_mm": )" + std::to_string(travel_mm) + R"(},)"
                                R"("cannula": {"enabled": false}, "tissue": )" + tissue + ","
                                R"("solver": {"mass_scaling_dt_ms": 1e-5},)"
                                R"("output": {"frames": )" + std::to_string(frames) + R"(, "history_interval_ms": 0.02}})");
  return run("run --scene " + (dir / "scene.json").string() + " --out " + (dir / "run").string() + " --quiet " + flags, true);
}

// The files of a finished run folder: the effective scene, the summary and the history.
struct RunFiles {
  nlohmann::json scene, summary;
  needle::CsvTable history;
};

// The plain rod pushed 0.8 mm into the small block (2 x 2.4 x 1.2 mm, 0.4 mm particles) with these flags; the run must succeed.
inline RunFiles run_rod_into_small_block(const std::string& name, const std::string& flags) {
  const fs::path dir = fresh_folder(name);
  const auto r = run_rod_into_block(dir, R"({"size_mm": [2, 2.4, 1.2], "spacing_mm": 0.4})", 0.8, 0, flags);
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  std::ifstream scene_file(dir / "run" / "scene.json"), summary_file(dir / "run" / "summary.json");
  return {nlohmann::json::parse(scene_file), nlohmann::json::parse(summary_file),
          needle::read_csv_table((dir / "run" / "history.csv").string())};
}

// The plain rod into the small block with flags the run must refuse: exit 2, the message, no run folder. Returns the output.
inline std::string refused_on_small_block(const std::string& name, const std::string& flags, const std::string& message) {
  const fs::path dir = fresh_folder(name);
  const auto bad = run_rod_into_block(dir, R"({"size_mm": [2, 2.4, 1.2], "spacing_mm": 0.4})", 0.8, 0, flags);
  INFO(flags << ": " << bad.out);
  CHECK(bad.exit_code == 2);
  CHECK(bad.out.find(message) != std::string::npos);
  CHECK(!fs::exists(dir / "run"));
  return bad.out;
}

// The same, and the refusal is one line.
inline void refused_in_one_line(const std::string& name, const std::string& flags, const std::string& message) {
  const std::string out = refused_on_small_block(name, flags, message);
  INFO(flags << ": " << out);
  CHECK(std::count(out.begin(), out.end(), '\n') == 1);
}

// A 26 mm SB (T4 0.5 mm, no cannula) pushed 0.8 mm into the small block.
inline RunFiles run_sb_into_small_block(const std::string& name, const std::string& flags, const std::string& needle = R"("preset": "SB")") {
  const fs::path dir = fresh_folder(name);
  write(dir / "scene.json", R"({"needle": {)" + needle + R"(, "length_mm": 26, "mesh": {"order": 1, "size_mm": 0.5}},)"
                            R"("motion": {"accel_time_ms": 0.02, "travel_mm": 0.8}, "cannula": {"enabled": false},)"
                            R"("tissue": {"size_mm": [2, 2.4, 1.2], "spacing_mm": 0.4}, "solver": {"mass_scaling_dt_ms": 1e-5},)"
                            R"("output": {"frames": 0, "history_interval_ms": 0.02}})");
  const auto r = run("run --scene " + (dir / "scene.json").string() + " --out " + (dir / "run").string() + " --quiet " + flags, true);
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  std::ifstream scene_file(dir / "run" / "scene.json"), summary_file(dir / "run" / "summary.json");
  return RunFiles{nlohmann::json::parse(scene_file), nlohmann::json::parse(summary_file),
                  needle::read_csv_table((dir / "run" / "history.csv").string())};
}

inline std::string message_of(const std::string& text) {
  try {
    needle::parse_scene(text, "scene.json");
  } catch (const needle::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace needle_test
