// The model levels on the command line (runs/model_levels.h): --model sets the needle model, the contact law and
// the tissue's mass scaling together, a wrong name or combination is refused with nothing written; `needle bench insertion` runs each level
// on one scene and writes the speed-against-error table from the runs' own summaries.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_run.h"
#include "run_fixtures.h"
#include "runs/csv_table.h"

namespace fs = std::filesystem;
using namespace needle_test;

TEST_CASE("needle run --model fast runs the implicit needle with the kinematic contact, bad levels are refused", "[apps][lspg][gmsh][slow]") {
  const RunFiles fast = run_sb_into_small_block("model_fast", "--model fast");
  CHECK(fast.scene["needle"]["model"] == "implicit");
  CHECK(fast.scene["tissue"]["contact"]["law"] == "projection");
  CHECK(fast.summary["model_level"] == "fast");
  CHECK(fast.summary["status"] == "finished");
  CHECK(fast.summary["needle_factorizations"].get<int>() >= 1);
  CHECK(fast.summary["particles_inside"].get<int>() == 0);
  // One needle step or a few per coupling step, where the explicit needle takes hundreds.
  CHECK(fast.summary["needle_steps"].get<long>() < 4 * fast.summary["steps"].get<long>());
  // The tissue mass-scaled to half the needle's step: the scene says so, the summary gives the target and what was added.
  CHECK(fast.scene["solver"]["tissue_mass_scaling"] == true);
  REQUIRE(fast.summary.contains("tissue_mass_scaling"));
  CHECK(fast.summary["tissue_mass_scaling"]["target_dt_ms"].get<double>() == Approx(0.5 * fast.summary["needle_time_step_ms"].get<double>()));
  // This small block's particles need no mass at half the needle's step; at twice the needle's step the
  // squeezed ones do, a bounded share of the block's, and the kinetic energy the mass changes take out is a small part of
  // what the drive put in.
  const nlohmann::json& half = fast.summary["tissue_mass_scaling"];
  CHECK((half["max_mass_ratio"].get<double>() > 1.0) == (half["max_added_mass_percent"].get<double>() > 0.0));
  const RunFiles coarse = run_sb_into_small_block(
      "model_fast_coarse", fmt::format("--model fast --set solver.tissue_mass_scaling_dt_ms={}", 2 * fast.summary["needle_time_step_ms"].get<double>()));
  const nlohmann::json& scaling = coarse.summary["tissue_mass_scaling"];
  CHECK(scaling["max_mass_ratio"].get<double>() > 1.0);
  CHECK(scaling["max_added_mass_percent"].get<double>() > 0.0);
  CHECK(scaling["max_added_mass_percent"].get<double>() < 5.0);
  CHECK(std::abs(scaling["kinetic_energy_added_mJ"].get<double>()) > 0.0);
  CHECK(std::abs(scaling["kinetic_energy_added_mJ"].get<double>()) < 0.01 * coarse.summary["energy_mJ"]["drive_work"].get<double>());
  CHECK(coarse.summary["steps"].get<long>() < fast.summary["steps"].get<long>());
  // Without it (a custom level) the run takes the tissue's own, smaller steps.
  const RunFiles unscaled = run_sb_into_small_block("model_fast_unscaled", "--model fast --set solver.tissue_mass_scaling=false");
  CHECK(unscaled.summary["model_level"] == "custom");
  CHECK(!unscaled.summary.contains("tissue_mass_scaling"));
  CHECK(unscaled.summary["steps"].get<long>() >= fast.summary["steps"].get<long>());
  const RunFiles full = run_sb_into_small_block("model_full", "--model full");
  CHECK(full.summary["model_level"] == "full");
  CHECK(full.summary["needle_steps"].get<long>() > 20 * full.summary["steps"].get<long>());
  CHECK(full.summary["steps"].get<long>() > 2 * fast.summary["steps"].get<long>());
  // What set each coupling step (issue 48): every step counted once; the full level's penalty contact sets most of its
  // steps (its stiffness caps the step), the fast level's kinematic contact none (the tissue's mass-scaled step does).
  const auto limits_sum = [](const nlohmann::json& limits) {
    long sum = 0;
    for (const auto& [name, count] : limits.items()) sum += count.get<long>();
    return sum;
  };
  for (const RunFiles* r : {&fast, &full, &unscaled}) {
    INFO(r->summary["coupling_step_limits"].dump());
    CHECK(limits_sum(r->summary["coupling_step_limits"]) == r->summary["steps"].get<long>());
  }
  CHECK(2 * full.summary["coupling_step_limits"]["contact"].get<long>() > full.summary["steps"].get<long>());
  CHECK(fast.summary["coupling_step_limits"]["contact"] == 0);
  CHECK(2 * fast.summary["coupling_step_limits"]["tissue"].get<long>() > fast.summary["steps"].get<long>());
  std::ifstream log_file(fs::temp_directory_path() / "needle_sim_model_fast" / "run" / "run.log");  // run_sb_into_small_block's folder
  const std::string log((std::istreambuf_iterator<char>(log_file)), std::istreambuf_iterator<char>());
  CHECK(log.find("the coupling step set by tissue ") != std::string::npos);
  refused_on_small_block("model_bad", "--model quick", "--model: unknown model level 'quick' (known: full, projection, fast)");
  refused_on_small_block("model_mixed", "--set needle.model=implicit", "needle.model implicit needs tissue.contact.law projection");
  refused_on_small_block("model_law", "--set tissue.contact.law=spring", "law: must be penalty or projection (got 'spring')");
  // A needle alone (no tissue; `needle simulate`) is the explicit FE needle's run: another needle model is refused with
  // one line and nothing written, not silently replaced by the FE needle (issue 49).
  const fs::path alone = fresh_folder("model_alone");
  write(alone / "scene.json", R"({"needle": {"plain_rod": true, "length_mm": 6, "mesh": {"order": 1, "size_mm": 0.5}},)"
                              R"("motion": {"accel_time_ms": 0.02, "travel_mm": 0.2}, "tissue": {"enabled": false},)"
                              R"("output": {"frames": 0}})");
  for (const char* model : {"implicit", "rigid"}) {
    const Result r = run(fmt::format("simulate {} --set needle.model={} --out {} --quiet", (alone / "scene.json").string(), model,
                                     (alone / "run").string()),
                         true);
    INFO(r.out);
    CHECK(r.exit_code == 2);
    CHECK(r.out.find(fmt::format("needle.model {}: a needle-alone run (tissue.enabled false) runs the explicit FE needle only", model)) !=
          std::string::npos);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
    CHECK(!fs::exists(alone / "run"));
  }
  const Result fe = run("simulate " + (alone / "scene.json").string() + " --out " + (alone / "run").string() + " --quiet", true);
  INFO(fe.out);
  CHECK(fe.exit_code == 0);
}

TEST_CASE("needle bench insertion writes one row per needle and level from the runs, reuses finished ones, refuses bad lists",
          "[apps][lspg][gmsh][slow]") {
  const fs::path dir = fresh_folder("bench_insertion");
  write(dir / "scene.json", R"({"needle": {"preset": "SB", "length_mm": 26, "mesh": {"order": 1, "size_mm": 0.5}},)"
                            R"("motion": {"accel_time_ms": 0.02, "travel_mm": 0.8}, "cannula": {"enabled": false},)"
                            R"("tissue": {"enabled": true, "size_mm": [2, 2.4, 1.2], "spacing_mm": 0.4}, "output": {"frames": 0}})");
  write(dir / "reference.json", R"({"travel_mm": 0.8, "deflection_mm": {"SB": -0.001}})");
  const std::string args = "bench insertion --scene " + (dir / "scene.json").string() + " --reference " + (dir / "reference.json").string() +
                           " --needles SB --levels projection,fast --threads 1 --out " + (dir / "out").string();
  const Result r = run(args, true);
  INFO(r.out);
  REQUIRE(r.exit_code == 0);
  const needle::CsvTable table = needle::read_csv_table((dir / "out" / "speed_error.csv").string());
  REQUIRE(table.rows.size() == 2);
  for (int k = 0; k < 2; ++k) {
    const fs::path run_dir = dir / "out" / (k == 0 ? "SB_projection" : "SB_fast");
    std::ifstream in(run_dir / "summary.json");
    const nlohmann::json summary = nlohmann::json::parse(in);
    // The table's numbers are the run's own, the error its deflection minus the reference's.
    CHECK(table.column("deflection_mm")[static_cast<size_t>(k)] == Approx(summary["deflection_mm"].get<double>()).epsilon(1e-12));
    CHECK(table.column("error_vs_reference_mm")[static_cast<size_t>(k)] == Approx(summary["deflection_mm"].get<double>() + 0.001).epsilon(1e-9));
    CHECK(table.column("coupling_steps")[static_cast<size_t>(k)] == summary["steps"].get<double>());
    // What ran beside it: the one thread asked for, of the machine's cores, and the machine's load average (what
    // /proc/loadavg said at the run's start and end: a number where Linux gives it).
    const nlohmann::json& machine = summary["machine"];
    CHECK(machine["threads_used"] == 1);
    CHECK(machine["cores"].get<int>() >= 1);
    CHECK(table.column("threads_used")[static_cast<size_t>(k)] == 1);
    CHECK(table.column("cores")[static_cast<size_t>(k)] == machine["cores"].get<double>());
    if (fs::exists("/proc/loadavg")) {
      CHECK(machine["load_average_1min_at_start"].get<double>() >= 0);
      CHECK(table.column("load_average_1min_at_end")[static_cast<size_t>(k)] == Approx(machine["load_average_1min_at_end"].get<double>()));
    }
  }
  CHECK(fs::exists(dir / "out" / "speed_error.png"));
  CHECK(fs::exists(dir / "out" / "speed_error.json"));
  // The Markdown table docs/insertion.md shows: a row a case, with what ran beside it.
  std::ifstream md_file(dir / "out" / "speed_error.md");
  const std::string md((std::istreambuf_iterator<char>(md_file)), std::istreambuf_iterator<char>());
  CHECK(md.find("| SB | projection | ") != std::string::npos);
  CHECK(md.find("| SB | fast | ") != std::string::npos);
  CHECK(md.find("1 thread of ") != std::string::npos);
  CHECK(md.find((dir / "reference.json").string()) != std::string::npos);
  // Again: both runs are reused, the table is the same.
  const Result again = run(args, true);
  CHECK(again.exit_code == 0);
  CHECK(again.out.find("reused") != std::string::npos);
  CHECK(needle::read_csv_table((dir / "out" / "speed_error.csv").string()).rows.size() == 2);
  // Bad lists and a reference of another travel are refused before any run.
  for (const auto& [flags, message] : {std::pair<std::string, std::string>{"--levels quick", "--levels: unknown model level 'quick'"},
                                       {"--needles ,", "--needles: give at least one needle"}}) {
    const Result bad = run("bench insertion --scene " + (dir / "scene.json").string() + " --reference '' " + flags + " --out " +
                               (dir / "bad").string(), true);
    INFO(flags << ": " << bad.out);
    CHECK(bad.exit_code == 2);
    CHECK(bad.out.find(message) != std::string::npos);
    CHECK(!fs::exists(dir / "bad"));
  }
  write(dir / "far.json", R"({"travel_mm": 10, "deflection_mm": {"SB": -0.2}})");
  const Result far = run("bench insertion --scene " + (dir / "scene.json").string() + " --reference " + (dir / "far.json").string() +
                             " --out " + (dir / "far").string(), true);
  CHECK(far.exit_code == 2);
  CHECK(far.out.find("was run to 10 mm, the scene goes 0.8 mm") != std::string::npos);
  CHECK(!fs::exists(dir / "far"));
}
