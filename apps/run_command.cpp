// `needle run`: the paper's insertion for a needle given by preset, d_a or recipe (or any scene), with
// the run defaults of docs/insertion.md, written to a run folder.
#include "apps/run_command.h"

#include <cmath>
#include <fmt/format.h>
#include <memory>

#include "apps/cli_checks.h"
#include "runs/insertion_run.h"
#include "runs/model_levels.h"
#include "apps/scene_overrides.h"
#include "runs/scene.h"
#include "runs/scene_request.h"
#include "core/input_error.h"

namespace needle {
namespace {

struct RunCommandOptions {
  std::string preset, recipe, scene_file, calibration_file;
  double d_a_mm = std::nan("");
  SceneOverrides overrides;
  double mass_scaling_dt_ms = std::nan("");
  double tissue_E_MPa = std::nan("");
  int frames = -1;
  bool no_subcycling = false, rigid = false;
  RunOptions run;
};

void run(const RunCommandOptions& o) {
  const int sources = !o.preset.empty() + !std::isnan(o.d_a_mm) + !o.recipe.empty();
  NEEDLE_REQUIRE(sources >= 1 || !o.scene_file.empty(), "give a needle (--preset, --d-a or --recipe) or a --scene");
  // The tissue's E: given, from a calibration, from the scene file, or (the run defaults) the SB calibration shipped
  // with the toolkit, so that the first run a user makes is the calibrated paper scene (runs/scene_request.h).
  SceneRequest request;
  request.scene_file = o.scene_file;
  request.preset = o.preset;
  request.d_a_mm = o.d_a_mm;
  request.recipe_file = o.recipe;
  request.model = o.overrides.model;
  request.tissue_E_MPa = o.tissue_E_MPa;
  request.calibration_file = o.calibration_file;
  if (!std::isnan(o.mass_scaling_dt_ms))
    request.command_settings.push_back({fmt::format("solver.mass_scaling_dt_ms={}", o.mass_scaling_dt_ms), fmt::format("--mass-scaling-dt-ms {}", o.mass_scaling_dt_ms)});
  if (o.frames >= 0) request.command_settings.push_back({fmt::format("output.frames={}", o.frames), fmt::format("--frames {}", o.frames)});
  if (o.no_subcycling) request.command_settings.push_back({"solver.subcycling=false", "--no-subcycling"});
  if (o.rigid) request.command_settings.push_back({"needle.model=\"rigid\"", "--rigid"});
  // The scene flags and --set come last: a --set tissue.material.E_MPa is the E the run takes.
  request.settings = scene_override_settings(o.overrides);
  const ResolvedScene resolved = resolve_scene(request);
  RunOptions run = o.run;
  run.note = fmt::format("tissue E {:g} MPa, {}", resolved.scene.tissue.material.E_MPa, resolved.E_source);
  run_insertion(resolved.scene, run);
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunCommandOptions>();
  CLI::App* c = app.add_subcommand("run", "Insert a needle into the paper's tissue block: CAD -> mesh -> particles -> L-SPG solve "
                                          "(docs/insertion.md)");
  c->add_option("--preset", o->preset, "Paper needle: SB, LMB, AMB or HMB");
  c->add_option("--d-a", o->d_a_mm, "Multi-bevel needle with this d_a (mm)");
  c->add_option("--recipe", o->recipe, "Grinding recipe (JSON)");
  c->add_option("--scene", o->scene_file, "Scene file (JSON) instead of the run defaults; tissue is switched on");
  c->add_option("--out", o->run.out_dir, "Run folder to create")->required();
  add_scene_override_options(c, o->overrides);
  add_scene_flag(c, o->overrides, "--mesh-size-mm", "Needle mesh size over the tip and groove (run default 0.4; paper 0.2; scene key needle.mesh.size_mm)");
  c->add_option("--mass-scaling-dt-ms", o->mass_scaling_dt_ms, "Needle selective mass scaling target step (run default 5e-6; 0: off)");
  c->add_option("--tissue-E-MPa", o->tissue_E_MPa,
                "Tissue Young's modulus (the calibrated parameter; default: the model level's SB calibration, data/paper/calibration_sb.json "
                "for the fast level, calibration_sb_full.json for the full and projection levels; the paper's card: 0.665)");
  c->add_option("--calibration", o->calibration_file, "Take the tissue's E from this calibration (`needle calibrate`'s calibration.json)");
  c->add_option("--frames", o->frames, "ParaView frames over the run (default 20; 0: none)")->check(count_check());
  c->add_flag("--no-subcycling", o->no_subcycling, "Tissue takes the needle's step (the plain full model; slow)");
  c->add_flag("--rigid", o->rigid, "Rigid needle (no deflection)");
  c->add_flag("--overwrite", o->run.overwrite, "Replace an existing run folder when the run ends");
  c->add_flag("--quiet", o->run.quiet, "No progress bar or result line");
  c->add_option("--threads", o->run.threads, "Worker threads (default: the scene's; 0: all cores)")->check(count_check());
  c->callback([o] { run(*o); });
}

}  // namespace needle
