// `needle paper`: runs SB, LMB, AMB and HMB on the paper's scene with the run defaults (or reuses runs
// already in the report folder with the same scene) and writes the report (apps/paper_report.h).
#include "apps/paper_command.h"

#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "apps/cli_checks.h"
#include "runs/insertion_run.h"
#include "apps/scene_overrides.h"
#include "runs/scene_request.h"
#include "runs/json_file.h"
#include "studies/paper_report.h"
#include "runs/scene.h"
#include "runs/writer_lock.h"
#include "core/input_error.h"

#ifndef NEEDLE_DATA_DIR
#define NEEDLE_DATA_DIR "data"
#endif

namespace needle {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

struct PaperOptions {
  std::string out_dir, needles = "SB,LMB,AMB,HMB", reference = std::string(NEEDLE_DATA_DIR) + "/paper/reference.json";
  std::string calibration_file;
  std::string fitted = std::string(NEEDLE_DATA_DIR) + "/paper/crushed_depth_hmb.json";
  std::vector<std::string> compare;  // LABEL=FILE, other reports' results.json
  std::vector<std::string> replicas;  // LABEL=FILE, this model's reports with a numerical detail changed
  std::string label = "this report";  // this report's row among the compared models
  double tissue_E_MPa = std::nan("");
  SceneOverrides overrides;
  bool report_only = false, rerun = false, no_tips = false, quiet = false;
  int threads = -1;
  std::string command_line;
};

std::vector<std::string> split_names(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ','))
    if (!name.empty()) out.push_back(name);
  NEEDLE_REQUIRE(!out.empty(), "--needles names no needle");
  for (const std::string& n : out)
    NEEDLE_REQUIRE(n == "SB" || n == "LMB" || n == "AMB" || n == "HMB", fmt::format("--needles: '{}' is not one of SB, LMB, AMB, HMB", n));
  return out;
}

void paper(const PaperOptions& o) {
  const std::vector<std::string> needles = split_names(o.needles);
  const std::vector<PaperReferenceNeedle> reference = read_paper_reference(o.reference);
  // The four needles' scene: the run defaults at the given E or calibration, or the shipped SB calibration of their model
  // level, as `needle run` takes it (issue 49: the card's E 0.665 MPa put SB at -4.19 mm); --report-only reads E from
  // the runs. Each needle's preset is set per run below.
  SceneRequest request;
  request.model = o.overrides.model;
  request.tissue_E_MPa = o.tissue_E_MPa;
  request.calibration_file = o.calibration_file;
  request.card_by_default = o.report_only;
  request.settings = scene_override_settings(o.overrides);
  const ResolvedScene resolved = resolve_scene(request);
  Scene scene = resolved.scene;
  std::string E_source = resolved.E_source;
  const std::string calibration_file = resolved.calibration_file;
  std::vector<ComparedModel> compare, replicas;
  for (const auto& [texts, flag, models] : {std::tuple{&o.compare, "--compare", &compare}, std::tuple{&o.replicas, "--replica", &replicas}})
    for (const std::string& c : *texts) {
      models->push_back(parse_compared_model(c, flag));
      NEEDLE_REQUIRE(fs::is_regular_file(models->back().results_path),
                     fmt::format("{} {}: no file '{}'", flag, models->back().label, models->back().results_path));
    }

  const fs::path dir = named_folder(o.out_dir);
  const fs::path parent = fs::absolute(dir).parent_path();
  NEEDLE_REQUIRE(fs::is_directory(parent), fmt::format("the folder '{}' that should hold the report does not exist", parent.string()));
  NEEDLE_REQUIRE(!fs::exists(dir) || fs::is_directory(dir), fmt::format("'{}' exists and is not a folder", dir.string()));
  const auto lock = lock_output_folder(dir);
  if (!o.report_only) {
    fs::create_directories(dir / "runs");
    for (const std::string& name : needles) {
      Scene s = scene;
      s.needle.preset = name;  // the run scene has no other needle source
      const fs::path folder = dir / "runs" / name;
      RunOptions run;
      run.out_dir = folder.string();
      run.overwrite = true;
      run.quiet = o.quiet;
      run.threads = o.threads;
      run.throw_on_stop = false;  // a stopped run is reported as such, with what it reached
      if (o.rerun) {
        run_insertion(s, run);
      } else if (run_insertion_unless_done(s, run) && !o.quiet) {
        fmt::print("{}: reused the run in {}\n", name, folder.string());
      }
    }
  }
  if (o.report_only) {
    // The report describes the runs in the folder: their E, whatever the defaults say. A flag that names another
    // E than the runs used would put a wrong number beside their results.
    double runs_E_MPa = std::nan("");
    std::string first;
    for (const std::string& name : needles) {
      const fs::path scene_path = dir / "runs" / name / "scene.json";
      if (!fs::is_regular_file(scene_path)) continue;  // the report names the missing run
      const double E = number_or_nan(read_json_file(scene_path.string(), "run scene").value("tissue", json::object()).value("material", json::object()),
                                     "E_MPa");
      if (std::isnan(E)) continue;
      if (first.empty()) {
        runs_E_MPa = E;
        first = name;
      }
      NEEDLE_REQUIRE(E == runs_E_MPa, fmt::format("the runs in '{}' disagree on the tissue's E: {} {} MPa, {} {} MPa",
                                                  (dir / "runs").string(), first, runs_E_MPa, name, E));
    }
    if (!std::isnan(runs_E_MPa)) {
      const bool E_given = !o.calibration_file.empty() || !std::isnan(o.tissue_E_MPa);
      NEEDLE_REQUIRE(!E_given || std::abs(scene.tissue.material.E_MPa - runs_E_MPa) <= 1e-12 * runs_E_MPa,
                     fmt::format("the runs in '{}' used E = {} MPa, not the {} MPa that {} gives", (dir / "runs").string(), runs_E_MPa,
                                 scene.tissue.material.E_MPa, o.calibration_file.empty() ? "--tissue-E-MPa" : o.calibration_file));
      if (!E_given) E_source = fmt::format("read from the runs' scene.json");
      scene.tissue.material.E_MPa = runs_E_MPa;
    }
  }
  PaperReportInput report;
  report.out_dir = dir.string();
  report.needles = needles;
  report.reference = reference;
  report.reference_path = o.reference;
  report.tissue_E_MPa = scene.tissue.material.E_MPa;
  report.tissue_E_source = E_source;
  report.calibration_path = calibration_file;
  report.fitted_path = o.fitted;
  report.command_line = o.command_line;
  report.draw_tips = !o.no_tips;
  report.compare = compare;
  report.replicas = replicas;
  report.label = o.label;
  write_paper_report(report);
  if (!o.quiet) fmt::print("wrote {}\n", (dir / "report.md").string());
}

}  // namespace

void add_paper_command(CLI::App& app) {
  auto o = std::make_shared<PaperOptions>();
  CLI::App* c = app.add_subcommand("paper", "Reproduce the paper: SB, LMB, AMB and HMB on the paper's scene, and a report with the "
                                            "deflection table, groove filling and plots (docs/paper.md)");
  c->add_option("--out", o->out_dir, "Report folder (created; runs go to OUT/runs/NAME)")->required();
  c->add_option("--needles", o->needles, "Comma-separated needles (default SB,LMB,AMB,HMB)");
  c->add_option("--tissue-E-MPa", o->tissue_E_MPa, "Tissue Young's modulus (default: the card's 0.665 MPa)");
  c->add_option("--calibration", o->calibration_file,
                "calibration.json from `needle calibrate` (its tissue_E_MPa; default: the shipped SB calibration of the model level, "
                "data/paper/calibration_sb.json for the default)");
  c->add_option("--fitted", o->fitted,
                 "The record of the parameter besides E fitted to a needle (default data/paper/crushed_depth_hmb.json, the crushed "
                 "lip's depth fitted on HMB): where the runs use its value the report names it as fitted, with its "
                 "leave-one-needle-out errors")
      ->check(CLI::ExistingFile);
  c->add_option("--reference", o->reference, "The paper's reference table (default data/paper/reference.json)");
  add_scene_override_options(c, o->overrides);
  add_scene_flag(c, o->overrides, "--mesh-size-mm", "Needle mesh size (run default 0.4; scene key needle.mesh.size_mm)");
  c->add_option("--compare", o->compare,
                "LABEL=FILE: set another report's results.json (another model: spacing, cut, E) beside this one in the report; "
                "repeatable");
  c->add_option("--replica", o->replicas,
                "LABEL=FILE: the results.json of a report of this same model whose runs differ only in a numerical detail, e.g. "
                "--tissue-entry-x-mm 0.1 (the lattice shifted against the path); the report gives each deflection's spread over "
                "the replicas and which targets hold in every one (docs/notebook/scripts/scatter_study.sh); repeatable");
  c->add_option("--label", o->label, "This report's name in the table of --compare (default 'this report')");
  c->add_flag("--report-only", o->report_only, "Only rewrite the report from the run folders already in OUT/runs");
  c->add_flag("--rerun", o->rerun, "Run every needle again even if OUT/runs holds a run of the same scene");
  c->add_flag("--no-tips", o->no_tips, "Skip the tip pictures (they need the CAD booleans, a few seconds each)");
  c->add_flag("--quiet", o->quiet, "No progress bars or result lines");
  c->add_option("--threads", o->threads, "Worker threads (default: the scene's; 0: all cores)")->check(count_check());
  c->callback([o, c] {
    // The command that regenerates the report (its runs are reused).
    std::string& line = o->command_line;
    line = fmt::format("needle paper --out {}", o->out_dir);
    if (c->count("--needles")) line += " --needles " + o->needles;
    if (c->count("--tissue-E-MPa")) line += fmt::format(" --tissue-E-MPa {}", o->tissue_E_MPa);
    if (c->count("--calibration")) line += " --calibration " + o->calibration_file;
    if (c->count("--reference")) line += " --reference " + o->reference;
    if (c->count("--fitted")) line += " --fitted " + o->fitted;
    line += scene_override_arguments(o->overrides);
    if (c->count("--label")) line += fmt::format(" --label \"{}\"", o->label);
    for (const std::string& c : o->compare) line += fmt::format(" --compare \"{}\"", c);
    for (const std::string& c : o->replicas) line += fmt::format(" --replica \"{}\"", c);
    paper(*o);
  });
}

}  // namespace needle
