// `needle simulate SCENE --out DIR`: builds the needle a scene describes, drives it through the
// cannula with the scene's profile and writes the run folder:
//   scene.json (the effective scene), history.csv, summary.json, needle.pvd + frames/*.vtu, run.log.
#include "apps/simulate_command.h"

#include <memory>

#include "apps/cli_checks.h"
#include "runs/insertion_run.h"
#include "runs/needle_alone_run.h"
#include "runs/scene.h"
#include "runs/scene_request.h"

namespace needle {
namespace {

struct SimulateOptions {
  std::string scene_file;
  std::vector<std::string> settings;
  RunOptions run;
};

// Everything that can be wrong with the input is found before the run folder exists.
void run_simulation(const SimulateOptions& o) {
  SceneRequest request;  // the scene file's own E and tissue, --set last (runs/scene_request.h)
  request.scene_file = o.scene_file;
  request.tissue_on = false;
  for (const std::string& setting : o.settings) request.settings.push_back({setting, "--set " + setting});
  const Scene scene = resolve_scene(request).scene;
  if (scene.tissue.enabled) run_insertion(scene, o.run);
  else run_needle_alone(scene, o.run);
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  CLI::App* c = app.add_subcommand("simulate", "Run a scene file (JSON) and write a run folder (docs/scenes.md)");
  c->add_option("scene", o->scene_file, "Scene file (JSON)")->required();
  c->add_option("--set", o->settings,
                "Set a scene key over the file's, KEY=VALUE with dotted names and units, e.g. --set tissue.material.E_MPa=0.1 (repeatable)");
  c->add_option("--out", o->run.out_dir, "Run folder to create")->required();
  c->add_flag("--overwrite", o->run.overwrite, "Replace an existing run folder when the run ends");
  c->add_flag("--quiet", o->run.quiet, "No progress bar or result line");
  c->add_option("--threads", o->run.threads, "Worker threads (default: the scene's solver.threads; 0: all cores)")->check(count_check());
  c->callback([o] { run_simulation(*o); });
}

}  // namespace needle
