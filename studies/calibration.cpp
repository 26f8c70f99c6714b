#include "studies/calibration.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "geometry/mesh_io.h"
#include "plot/line_plot.h"
#include "runs/insertion_run.h"
#include "runs/json_file.h"
#include "runs/provenance_json.h"
#include "runs/writer_lock.h"
#include "studies/calibration_steps.h"

namespace needle {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

struct Evaluation {
  double E_MPa = 0, deflection_mm = 0, insertion_mm = 0, runtime_s = 0;
  std::string status, folder;
};

Evaluation read_evaluation(double E, const fs::path& folder) {
  const json s = read_json_file((folder / "summary.json").string(), "run summary");
  Evaluation e;
  e.E_MPa = E;
  e.deflection_mm = s.at("deflection_mm").get<double>();
  e.insertion_mm = s.at("insertion_mm").get<double>();
  e.runtime_s = s.at("runtime_s").get<double>();
  e.status = s.at("status").get<std::string>();
  e.folder = folder.string();
  return e;
}

Evaluation evaluate(const Scene& base, double E, const fs::path& runs_dir, const CalibrationRequest& o) {
  Scene scene = base;
  scene.tissue.material.E_MPa = E;
  scene.tissue.material.validate();
  const fs::path folder = runs_dir / fmt::format("E_{:.6g}MPa", E);
  RunOptions run;
  run.out_dir = folder.string();
  run.overwrite = true;
  run.quiet = o.quiet;
  run.threads = o.threads;
  run.throw_on_stop = false;
  const bool reused = run_insertion_unless_done(scene, run);
  if (!o.quiet) fmt::print("E = {:.6g} MPa: {} {}\n", E, reused ? "reused" : "ran", folder.string());
  return read_evaluation(E, folder);
}

// The runs of this scene at other E than those in `have` already in runs_dir (folders E_<value>MPa whose
// scene.json is the scene at that E), by E. Folders of another scene, partial runs and other files are passed over.
std::vector<Evaluation> runs_already_there(const Scene& base, const fs::path& runs_dir, const std::vector<Evaluation>& have) {
  std::vector<Evaluation> found;
  for (const fs::directory_entry& entry : fs::directory_iterator(runs_dir)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_directory() || name.rfind("E_", 0) != 0 || !fs::is_regular_file(entry.path() / "scene.json")) continue;
    double E = std::nan("");
    try {
      E = read_json_file((entry.path() / "scene.json").string(), "run scene").at("tissue").at("material").at("E_MPa").get<double>();
    } catch (const std::exception&) {
      continue;  // not a run scene
    }
    const bool known = std::any_of(have.begin(), have.end(), [&](const Evaluation& e) { return std::abs(e.E_MPa - E) <= 1e-12 * E; });
    if (known || !(E > 0)) continue;
    Scene scene = base;
    scene.tissue.material.E_MPa = E;
    if (folder_holds_run_of(scene, entry.path().string())) found.push_back(read_evaluation(E, entry.path()));
  }
  std::sort(found.begin(), found.end(), [](const Evaluation& a, const Evaluation& b) { return a.E_MPa < b.E_MPa; });
  return found;
}

}  // namespace

CalibrationResult calibrate_tissue_E(const CalibrationRequest& o) {
  NEEDLE_REQUIRE(o.preset == "SB" || o.preset == "LMB" || o.preset == "AMB" || o.preset == "HMB",
                 fmt::format("--preset '{}' is not one of SB, LMB, AMB, HMB", o.preset));
  NEEDLE_REQUIRE(std::isfinite(o.target_mm) && o.target_mm != 0, "--target-deflection-mm must be a non-zero number (SB: -1.14)");
  NEEDLE_REQUIRE(std::isfinite(o.tolerance_mm) && o.tolerance_mm > 0, "--tolerance-mm must be positive");
  NEEDLE_REQUIRE(o.max_runs >= 1 && o.max_runs <= 20, "--max-runs must lie in [1, 20]");
  NEEDLE_REQUIRE(std::isfinite(o.sensitivity_step) && o.sensitivity_step >= 0 && o.sensitivity_step <= 1,
                 "--sensitivity-step must lie in [0, 1] (a relative change of E; 0: no sensitivity run)");
  const Scene& scene = o.scene;
  NEEDLE_REQUIRE(!scene.cannula_firing.enabled,
                 "needle calibrate reads the deflection at the end of the insertion; firing the cannula after it changes nothing it "
                 "reads and nearly doubles each run: drop --fire-cannula (scene key cannula.firing.enabled)");
  const double start = std::isnan(o.start_E_MPa) ? scene.tissue.material.E_MPa : o.start_E_MPa;
  NEEDLE_REQUIRE(std::isfinite(start) && start > 0, "--start-E-MPa must be positive");
  const fs::path dir = named_folder(o.out_dir);
  NEEDLE_REQUIRE(fs::is_directory(fs::absolute(dir).parent_path()),
                 fmt::format("the folder '{}' that should hold the calibration does not exist", fs::absolute(dir).parent_path().string()));
  const auto lock = lock_output_folder(dir);
  fs::create_directories(dir / "runs");

  std::vector<Evaluation> runs;
  auto points = [&] {
    std::vector<CalibrationPoint> p;
    for (const Evaluation& e : runs) p.push_back({e.E_MPa, e.deflection_mm, e.status == "finished"});
    return p;
  };
  auto converged = [&](const Evaluation& e) { return e.status == "finished" && std::abs(e.deflection_mm - o.target_mm) <= o.tolerance_mm; };
  runs.push_back(evaluate(scene, start, dir / "runs", o));
  while (!converged(runs.back()) && static_cast<int>(runs.size()) < o.max_runs)
    runs.push_back(evaluate(scene, next_calibration_E_MPa(points(), o.target_mm), dir / "runs", o));

  // Runs of the same scene already there count too, so none is repeated. The best run's slope comes from
  // the finished run nearest to it in E, made here when none lies within twice the sensitivity step.
  for (const Evaluation& e : runs_already_there(scene, dir / "runs", runs)) {
    if (!o.quiet) fmt::print("E = {:.6g} MPa: already there, {}\n", e.E_MPa, e.folder);
    runs.push_back(e);
  }
  std::size_t best_index = nearest_to_target(points(), o.target_mm);
  if (o.sensitivity_step > 0 && converged(runs[best_index]) && needs_sensitivity_run(points(), best_index, o.sensitivity_step)) {
    if (!o.quiet) fmt::print("sensitivity run at E (1 + {:g})\n", o.sensitivity_step);
    runs.push_back(evaluate(scene, runs[best_index].E_MPa * (1 + o.sensitivity_step), dir / "runs", o));
    best_index = nearest_to_target(points(), o.target_mm);
  }
  const Evaluation best = runs[best_index];
  const std::vector<CalibrationPoint> final_points = points();
  const std::optional<std::size_t> partner = nearest_in_E(final_points, best_index);
  double slope = std::nan("");
  if (partner && best.status == "finished") slope = sensitivity_mm_per_MPa(final_points[best_index], final_points[*partner]);
  json list = json::array();
  for (const Evaluation& e : runs)
    list.push_back({{"E_MPa", e.E_MPa}, {"deflection_mm", e.deflection_mm}, {"status", e.status}, {"insertion_mm", e.insertion_mm},
                    {"runtime_s", e.runtime_s}, {"run_folder", fs::relative(e.folder, dir).string()}});
  const json out = {{"needle", o.preset},
                    {"target_deflection_mm", o.target_mm},
                    {"tolerance_mm", o.tolerance_mm},
                    {"converged", converged(best)},
                    {"tissue_E_MPa", best.E_MPa},
                    {"deflection_mm", best.deflection_mm},
                    {"sensitivity_mm_per_MPa", std::isfinite(slope) ? json(slope) : json(nullptr)},
                    {"relative_sensitivity", std::isfinite(slope) ? json(slope * best.E_MPa / best.deflection_mm) : json(nullptr)},
                    {"sensitivity_from_E_MPa", std::isfinite(slope) ? json::array({best.E_MPa, runs[*partner].E_MPa}) : json(nullptr)},
                    {"runs", list},
                    {"provenance", provenance_json()}};
  write_file_atomically((dir / "calibration.json").string(), [&](const std::string& scratch) { std::ofstream(scratch) << out.dump(2) << "\n"; });
  LinePlot plot;
  plot.title = fmt::format("Calibration of the tissue's E on {} (target {:+.2f} mm)", o.preset, o.target_mm);
  plot.x_label = "tissue Young's modulus E (MPa)";
  plot.y_label = "deflection at the end (mm)";
  std::vector<Evaluation> by_E = runs;
  std::sort(by_E.begin(), by_E.end(), [](const auto& a, const auto& b) { return a.E_MPa < b.E_MPa; });
  PlotSeries line{"runs", {}, {}, plot_color(0), false, true};
  for (const Evaluation& e : by_E) line.x.push_back(e.E_MPa), line.y.push_back(e.deflection_mm);
  double lo = line.x.front(), hi = line.x.back();
  PlotSeries target{"target", {lo, hi}, {o.target_mm, o.target_mm}, plot_color(1), true, false};
  plot.series = {line, target};
  const RgbImage image = draw_line_plot(plot);
  write_file_atomically((dir / "calibration.png").string(), [&](const std::string& scratch) { write_png(image, scratch); });
  if (!o.quiet)
    fmt::print("{}: E = {:.4g} MPa gives {:+.3f} mm (target {:+.3f}, {}); wrote {}\n", o.preset, best.E_MPa, best.deflection_mm, o.target_mm,
               converged(best) ? "within tolerance" : "NOT within tolerance", (dir / "calibration.json").string());
  return {best.E_MPa, best.deflection_mm, converged(best), (dir / "calibration.json").string()};
}


}  // namespace needle
