#include "apps/bench_command.h"

#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <memory>
#include <sstream>

#include "apps/cli_checks.h"
#include "core/input_error.h"
#include "runs/insertion_run.h"
#include "runs/scene_request.h"
#include "runs/json_file.h"
#include "runs/model_levels.h"
#include "studies/speed_error.h"

#ifndef NEEDLE_DATA_DIR
#define NEEDLE_DATA_DIR "data"
#endif

namespace needle {
namespace {

struct BenchOptions {
  std::string out_dir, needles = "SB,LMB,AMB,HMB", levels = "full,projection,fast";
  std::string scene = std::string(NEEDLE_DATA_DIR) + "/scenes/bench_insertion_10mm.json";
  std::string reference = std::string(NEEDLE_DATA_DIR) + "/bench/insertion_reference_10mm.json";
  bool quiet = false;
  int threads = -1;
};

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> items;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) items.push_back(item);
  return items;
}

void bench_insertion(const BenchOptions& o) {
  const std::vector<std::string> needles = split(o.needles), levels = split(o.levels);
  NEEDLE_REQUIRE(!needles.empty(), "--needles: give at least one needle, e.g. SB,AMB");
  NEEDLE_REQUIRE(!levels.empty(), "--levels: give at least one model level, e.g. full,fast");
  // Everything is checked before the first run: the scene, each needle's and level's scene, the reference.
  const Scene base = read_scene(o.scene);
  nlohmann::json reference = nlohmann::json::object();
  std::string reference_source = "none";
  if (!o.reference.empty()) {
    const nlohmann::json r = read_json_file(o.reference, "reference");
    NEEDLE_REQUIRE(r.contains("deflection_mm") && r["deflection_mm"].is_object() && r.contains("travel_mm") && r["travel_mm"].is_number(),
                   fmt::format("the reference '{}' needs deflection_mm (an object by needle) and travel_mm", o.reference));
    NEEDLE_REQUIRE(std::abs(r["travel_mm"].get<double>() - base.motion.travel_mm) < 1e-9,
                   fmt::format("the reference '{}' was run to {} mm, the scene goes {} mm", o.reference, r["travel_mm"].get<double>(),
                               base.motion.travel_mm));
    reference = r["deflection_mm"];
    reference_source = o.reference;
  }
  struct Case {
    std::string needle, level, folder;
    Scene scene;
  };
  std::vector<Case> cases;
  for (const std::string& needle : needles)
    for (const std::string& level : levels) {
      SceneRequest request;  // the bench scene's own E, each needle at each level (runs/scene_request.h)
      request.scene_file = o.scene;
      request.preset = needle;
      request.model = level;
      request.model_where = "--levels";
      cases.push_back({needle, level, (std::filesystem::path(o.out_dir) / fmt::format("{}_{}", needle, level)).string(), resolve_scene(request).scene});
    }
  std::filesystem::create_directories(o.out_dir);
  std::vector<SpeedErrorCase> results;
  for (size_t k = 0; k < cases.size(); ++k) {
    const Case& c = cases[k];
    if (!o.quiet) fmt::print("[{}/{}] {} at the {} level -> {}\n", k + 1, cases.size(), c.needle, c.level, c.folder);
    RunOptions run;
    run.out_dir = c.folder;
    run.quiet = o.quiet;
    run.threads = o.threads;
    run.throw_on_stop = false;
    run.note = fmt::format("needle bench insertion: {} at the {} level", c.needle, c.level);
    if (run_insertion_unless_done(c.scene, run) && !o.quiet) fmt::print("  (a finished run of this scene was there: reused)\n");
    results.push_back(speed_error_case(c.needle, c.level, read_json_file((std::filesystem::path(c.folder) / "summary.json").string(), "summary")));
  }
  fill_errors(results, reference);
  write_speed_error_report(results, o.out_dir, reference_source);
  if (!o.quiet) {
    fmt::print("\n{}", speed_error_table(results));
    fmt::print("reference: {}\nwritten: {}/speed_error.csv, speed_error.json, speed_error.png, speed_error.md\n", reference_source, o.out_dir);
  }
}

}  // namespace

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks that print figures: speed against error of the solver's model levels");
  bench->require_subcommand(1);
  auto o = std::make_shared<BenchOptions>();
  std::string levels;
  for (const ModelLevel& level : model_levels()) levels += (levels.empty() ? "" : ", ") + level.name;
  CLI::App* c = bench->add_subcommand(
      "insertion", "Run each needle at each model level on one scene (default: 10 mm, data/scenes/bench_insertion_10mm.json) and "
                   "report time, steps, deflection, its error against a stored converged reference and against the full model, "
                   "penetration and energy error: speed_error.csv, .json and .png (a finished case folder is reused)");
  c->add_option("--out", o->out_dir, "Folder for the case runs and the report")->required();
  c->add_option("--needles", o->needles, "Comma-separated presets (default SB,LMB,AMB,HMB: the four the stored reference holds)");
  c->add_option("--levels", o->levels, fmt::format("Comma-separated model levels (default full,projection,fast; known: {})", levels));
  c->add_option("--scene", o->scene, "The scene (default data/scenes/bench_insertion_10mm.json)");
  c->add_option("--reference", o->reference,
                "Stored reference deflections for the scene (default data/bench/insertion_reference_10mm.json; empty: none)");
  c->add_option("--threads", o->threads, "Worker threads (default: the scene's; 0: all cores)")->check(count_check());
  c->add_flag("--quiet", o->quiet, "No progress or table");
  c->callback([o] { bench_insertion(*o); });
}

}  // namespace needle
