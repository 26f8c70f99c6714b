// `needle simulate SCENE --out DIR`: builds the needle a scene describes, drives it through the
// cannula with the scene's profile and writes the run folder:
//   scene.json (the effective scene), history.csv, summary.json, needle.pvd + frames/*.vtu, run.log.
#include "apps/simulate_command.h"

#include <chrono>
#include <fmt/format.h>
#include <fstream>
#include <iostream>

#include "apps/insertion_run.h"
#include "apps/run_folder.h"
#include "apps/scene.h"
#include "apps/scene_needle.h"
#include "core/input_error.h"
#include "solver/needle/needle_dynamics.h"
#include "solver/needle/needle_stiffness.h"
#include "core/parallel.h"
#include "core/solver_error.h"

namespace needle {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

struct SimulateOptions {
  std::string scene_file, out_dir;
  bool overwrite = false, quiet = false;
  int threads = -1;
};

void write_frame(const RunFolder& folder, const NeedleDynamics& run, int index, std::vector<std::pair<double, std::string>>& frames) {
  const std::string name = fmt::format("frames/needle_{:04}.vtu", index);
  write_needle_vtu(folder.path(name).string(), run);
  frames.emplace_back(run.time_ms(), name);
}

void run_simulation(const SimulateOptions& o) {
  // Everything that can be wrong with the input is found before the run folder exists.
  const Scene scene = read_scene(o.scene_file);
  if (scene.tissue.enabled) {
    RunOptions run;
    run.out_dir = o.out_dir;
    run.overwrite = o.overwrite;
    run.quiet = o.quiet;
    run.threads = o.threads;
    run_insertion(scene, run);
    return;
  }
  const ThreadLimit threads(o.threads >= 0 ? o.threads : scene.solver.threads);
  RunFolder folder(o.out_dir, o.overwrite);
  std::filesystem::create_directories(folder.path("frames"));
  RunLog log(folder.path("run.log"));
  {
    std::ofstream effective(folder.path("scene.json"));
    effective << scene_to_json(scene).dump(2) << "\n";
  }
  log.line(fmt::format("scene {}", scene.source));

  const auto start = Clock::now();
  const SceneNeedle built = build_scene_needle(scene.needle);
  log.line(fmt::format("needle {}: {} T{} elements, {} nodes, meshed in {:.2f} s", built.name, built.mesh.num_tets(),
                       built.mesh.order == 2 ? 10 : 4, built.mesh.num_nodes(), built.mesh_seconds));
  const FeNeedle needle(built.mesh, scene.needle.material, scene.solver.mass_scaling_dt_ms);
  log.line(fmt::format("stable step {:.4g} ms (unscaled {:.4g} ms); mass {:.5g} g, added by mass scaling {:.3g} % in {} elements",
                       needle.stable_time_step_ms(), needle.unscaled_time_step_ms(), needle.physical_mass_g(),
                       100 * needle.added_mass_g() / needle.physical_mass_g(), needle.mass_scaled_elements()));

  const NeedleSupports supports = driven_base_supports(needle.mesh(), scene.motion, scene.direction);
  const NeedleDynamicsOptions dynamics = scene_dynamics_options(scene);
  NeedleDynamics run(needle, supports, scene.cannula.enabled ? std::optional<CannulaOptions>(scene.cannula) : std::nullopt, dynamics);
  const int tip = nearest_node(needle.mesh(), built.tip_point);
  const double end_ms = scene.motion.end_time_ms();
  log.line(fmt::format("run to {:.6g} ms with dt {:.4g} ms: about {:.0f} steps", end_ms, run.time_step_ms(), end_ms / run.time_step_ms()));

  std::ofstream history(folder.path("history.csv"));
  history << "time_ms,insertion_mm,tip_dx_mm,tip_dy_mm,tip_dz_mm,deflection_mm,base_reaction_x_N,base_reaction_y_N,"
             "base_reaction_z_N,kinetic_mJ,strain_mJ,drive_work_mJ,cannula_work_mJ,energy_balance_error,"
             "cannula_contact_nodes,cannula_max_penetration_mm,cannula_force_y_N\n";
  double max_balance = 0, max_penetration = 0;
  int max_contacts = 0;
  auto record = [&] {
    const Eigen::RowVector3d u = run.positions_mm().row(tip) - needle.mesh().X.row(tip);
    const Eigen::Vector3d drive = run.drive_displacement_mm(), reaction = run.drive_reaction_N();
    const NeedleEnergy& e = run.energy();
    const CannulaContact& c = run.cannula_contact();
    history << fmt::format("{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.6g},{},{:.6g},{:.6g}\n",
                           run.time_ms(), drive.norm(), u.x(), u.y(), u.z(), u.y() - drive.y(), reaction.x(), reaction.y(),
                           reaction.z(), e.kinetic_mJ, e.strain_mJ, e.drive_work_mJ, e.cannula_work_mJ, e.balance_error(),
                           c.nodes_in_contact, c.max_penetration_mm, c.force_N.y());
  };
  std::vector<std::pair<double, std::string>> frames;
  record();
  if (scene.output.frames > 0) write_frame(folder, run, 0, frames);

  ProgressBar progress(end_ms, o.quiet);
  std::string status = "finished", reason;
  double next_history = scene.output.history_interval_ms;
  int next_frame = 1;
  const auto solve_start = Clock::now();
  try {
    while (run.time_ms() < end_ms - 1e-12) {
      run.step(end_ms);
      const double balance = run.energy().balance_error();
      if (std::abs(run.energy().drive_work_mJ) > 1e-6) max_balance = std::max(max_balance, balance);
      max_penetration = std::max(max_penetration, run.cannula_contact().max_penetration_mm);
      max_contacts = std::max(max_contacts, run.cannula_contact().nodes_in_contact);
      if (run.time_ms() >= next_history - 1e-12 || run.time_ms() >= end_ms - 1e-12) {
        record();
        next_history += scene.output.history_interval_ms;
      }
      if (scene.output.frames > 0 && run.time_ms() >= next_frame * end_ms / scene.output.frames - 1e-12) {
        write_frame(folder, run, next_frame++, frames);
      }
      progress.update(run.time_ms(), run.steps(), "ms");
    }
  } catch (const SolverError& e) {
    status = "stopped";
    reason = e.what();
    record();
  }
  progress.finish();
  const double solve_s = std::chrono::duration<double>(Clock::now() - solve_start).count();
  history.close();
  write_pvd(folder.path("needle.pvd"), frames);

  const Eigen::RowVector3d u = run.positions_mm().row(tip) - needle.mesh().X.row(tip);
  const double deflection = u.y() - run.drive_displacement_mm().y();
  const json summary = {
      {"status", status},
      {"reason", reason},
      {"needle", built.name},
      {"deflection_mm", deflection},
      {"tip_displacement_mm", {u.x(), u.y(), u.z()}},
      {"insertion_mm", run.drive_displacement_mm().norm()},
      {"time_ms", run.time_ms()},
      {"steps", run.steps()},
      {"time_step_ms", run.time_step_ms()},
      {"unscaled_time_step_ms", needle.unscaled_time_step_ms()},
      {"mass_g", needle.physical_mass_g()},
      {"added_mass_percent", 100 * needle.added_mass_g() / needle.physical_mass_g()},
      {"energy_balance_error", run.energy().balance_error()},
      {"max_energy_balance_error", max_balance},
      {"max_cannula_penetration_mm", max_penetration},
      {"max_cannula_contact_nodes", max_contacts},
      {"runtime_s", std::chrono::duration<double>(Clock::now() - start).count()},
      {"solve_s", solve_s},
      {"steps_per_s", run.steps() / std::max(solve_s, 1e-9)},
      {"peak_memory_MiB", peak_memory_MiB()},
      {"mesh", {{"order", needle.mesh().order}, {"elements", needle.num_elements()}, {"nodes", needle.num_nodes()},
                {"straightened_tets", needle.mesh().straightened_tets}}},
      {"threads", hardware_threads()},
  };
  {
    std::ofstream out(folder.path("summary.json"));
    out << summary.dump(2) << "\n";
  }
  log.line(fmt::format("{}{}: deflection {:.6g} mm after {} steps in {:.2f} s ({:.0f} steps/s), energy balance error {:.3g}",
                       status, reason.empty() ? "" : " (" + reason + ")", deflection, run.steps(), solve_s,
                       run.steps() / std::max(solve_s, 1e-9), run.energy().balance_error()));
  folder.commit();
  if (!o.quiet)
    fmt::print("{} {}: deflection {:.6g} mm, {} steps, {:.1f} s -> {}\n", built.name, status, deflection, run.steps(), solve_s,
               folder.final_path().string());
  if (status != "finished") throw SolverError(reason + fmt::format(" (what was written so far is in {})", o.out_dir));
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  CLI::App* c = app.add_subcommand("simulate", "Run a scene file (JSON) and write a run folder (docs/scenes.md)");
  c->add_option("scene", o->scene_file, "Scene file (JSON)")->required();
  c->add_option("--out", o->out_dir, "Run folder to create")->required();
  c->add_flag("--overwrite", o->overwrite, "Replace an existing run folder when the run ends");
  c->add_flag("--quiet", o->quiet, "No progress bar or result line");
  c->add_option("--threads", o->threads, "Worker threads (default: the scene's solver.threads; 0: all cores)");
  c->callback([o] { run_simulation(*o); });
}

}  // namespace needle
