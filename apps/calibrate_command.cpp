// `needle calibrate`: the tissue's E from one needle's measured deflection. The flags only; the calibration study
// (the runs, the secant, the sensitivity run, calibration.json and .png) is studies/calibration.h.
#include "apps/calibrate_command.h"

#include <cmath>
#include <memory>

#include "apps/cli_checks.h"
#include "apps/scene_overrides.h"
#include "runs/scene_request.h"
#include "runs/insertion_run.h"
#include "studies/calibration.h"

namespace needle {

namespace {

struct CalibrateOptions {
  CalibrationRequest request;
  SceneOverrides overrides;
};

void calibrate(CalibrateOptions o) {
  // Calibration starts from the run defaults' scene with the command's keys and the card's E (or --start-E-MPa): the E
  // it finds is what the shipped calibrations hold, so it cannot start from one (runs/scene_request.h).
  SceneRequest request;
  request.preset = o.request.preset;
  request.model = o.overrides.model;
  request.card_by_default = true;
  request.settings = scene_override_settings(o.overrides);
  o.request.scene = resolve_scene(request).scene;
  calibrate_tissue_E(o.request);
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto o = std::make_shared<CalibrateOptions>();
  CLI::App* c = app.add_subcommand("calibrate", "Find the tissue E for which a needle's paper insertion ends at a measured deflection "
                                                "(secant on full runs; docs/paper.md)");
  c->add_option("--preset", o->request.preset, "The needle to calibrate on (default SB: the paper's calibration needle)");
  c->add_option("--target-deflection-mm", o->request.target_mm, "Measured deflection at the end (SB: -1.14)")->required();
  c->add_option("--out", o->request.out_dir, "Calibration folder (created; runs go to OUT/runs/E_<E>MPa)")->required();
  c->add_option("--start-E-MPa", o->request.start_E_MPa, "First E to run (default: the card's 0.665)");
  c->add_option("--tolerance-mm", o->request.tolerance_mm, "Stop when within this of the target (default 0.05)");
  c->add_option("--max-runs", o->request.max_runs, "Most runs to make toward the target (default 4)");
  c->add_option("--sensitivity-step", o->request.sensitivity_step,
                "Relative change of E for one extra run after convergence that measures d delta / d E, made unless a finished "
                "run lies within twice this, this calibration's or one of the same scene already in OUT/runs (default 0.2; 0: none)");
  add_scene_override_options(c, o->overrides);
  c->add_flag("--quiet", o->request.quiet, "No progress bars or result lines");
  c->add_option("--threads", o->request.threads, "Worker threads (default: the scene's; 0: all cores)")->check(count_check());
  c->callback([o] { calibrate(*o); });
}

}  // namespace needle
