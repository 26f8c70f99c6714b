#pragma once
// The coupled L-SPG insertion of a scene (tissue.enabled): needle, particles, contact, solve, and the
// run folder (docs/scenes.md): scene.json, history.csv, facet_forces.csv, summary.json, needle.pvd and
// tissue.pvd with frames/, run.log. Used by `needle simulate` and `needle run`.
#include <string>

#include "apps/scene.h"

namespace needle {

struct RunOptions {
  std::string out_dir;
  bool overwrite = false, quiet = false;
  int threads = -1;  // -1: the scene's solver.threads
};

// InputError (nothing written) for bad input; SolverError after writing the folder if the solver stopped.
void run_insertion(const Scene& scene, const RunOptions& options);

}  // namespace needle
