#include "runs/run_driver.h"

#include <chrono>
#include <fmt/format.h>
#include <fstream>

#include "core/interrupt.h"
#include "core/machine_load.h"
#include "core/parallel.h"
#include "core/solver_error.h"
#include "runs/provenance_json.h"

namespace needle {

void drive_run(const Scene& scene, const RunOptions& o, const std::function<std::unique_ptr<RunModel>()>& build) {
  using Clock = std::chrono::steady_clock;
  const ThreadLimit threads(o.threads >= 0 ? o.threads : scene.solver.threads);
  const auto start = Clock::now();
  const MachineLoad load_at_start = machine_load();  // what ran beside the run, for its timings
  const InterruptWatch interrupts;  // Ctrl-C or SIGTERM: stop between steps and write what there is
  RunFolder::check_target(o.out_dir, o.overwrite);  // a bad --out is refused before the seconds of setup
  const std::unique_ptr<RunModel> built = build();
  RunModel& model = *built;
  if (const int signal = interrupts.signal())
    throw Interrupted(signal, fmt::format("interrupted by {} while the model was built; nothing written", signal_name(signal)));
  if (!o.quiet && !o.note.empty()) fmt::print("{}\n", o.note);
  if (!o.quiet)
    for (const std::string& note : scene.notes) fmt::print(stderr, "needle: note: {}\n", note);
  RunFolder folder(o.out_dir, o.overwrite);
  std::filesystem::create_directories(folder.path("frames"));
  RunLog log(folder.path("run.log"));
  {
    std::ofstream effective(folder.path("scene.json"));
    effective << scene_to_json(scene).dump(2) << "\n";
  }
  log.line(fmt::format("scene {}", scene.source));
  if (!o.note.empty()) log.line(o.note);
  for (const std::string& note : scene.notes) log.line("note: " + note);
  for (const std::string& line : model.setup_log()) log.line(line);

  const double end_ms = model.end_time_ms();
  model.open_outputs(folder);
  model.record();
  if (scene.output.frames > 0) model.frame(folder);
  ProgressBar progress(end_ms, o.quiet);
  std::string status = "finished", reason;
  double next_history = scene.output.history_interval_ms;
  int next_frame = 1;
  const auto solve_start = Clock::now();
  try {
    while (model.time_ms() < end_ms - 1e-12) {
      model.step(end_ms);
      if (model.time_ms() >= next_history - 1e-12 || model.time_ms() >= end_ms - 1e-12) {
        model.record();
        next_history += scene.output.history_interval_ms;
      }
      if (scene.output.frames > 0 && model.time_ms() >= next_frame * end_ms / scene.output.frames - 1e-12) {
        model.frame(folder);
        ++next_frame;
      }
      progress.update(model.time_ms(), model.steps(), "ms");
      if (const int signal = interrupts.signal()) {
        status = "interrupted";
        reason = fmt::format("interrupted by {} at t = {:.6g} ms of {:.6g}", signal_name(signal), model.time_ms(), end_ms);
        model.record();
        break;
      }
    }
  } catch (const SolverError& e) {
    status = "stopped";
    reason = e.what();
    model.record();
  }
  progress.finish();
  const double solve_s = std::chrono::duration<double>(Clock::now() - solve_start).count();
  model.close_outputs(folder);

  const Eigen::Vector3d u = model.tip_displacement_mm(), drive = model.drive_displacement_mm();
  const double deflection = u.y() - drive.y();
  nlohmann::json summary = {
      {"status", status},
      {"reason", reason},
      {"needle", model.needle_name()},
      {"deflection_mm", deflection},
      {"tip_displacement_mm", {u.x(), u.y(), u.z()}},
      {"insertion_mm", drive.norm()},
      {"time_ms", model.time_ms()},
      {"steps", model.steps()},
      {"energy_balance_error", model.energy_balance_error()},
      {"max_energy_balance_error", model.max_energy_balance_error()},
      {"runtime_s", std::chrono::duration<double>(Clock::now() - start).count()},
      {"solve_s", solve_s},
      {"peak_memory_MiB", peak_memory_MiB()},
      {"threads", hardware_threads()},
      {"provenance", provenance_json()},
  };
  // The run's timings with what ran beside them: the threads it used of the machine's cores, and the machine's 1-minute
  // load average as it started and as it ended (the run's own threads count in the second).
  const MachineLoad load_at_end = machine_load();
  summary["machine"] = {{"cores", load_at_end.cores},
                        {"threads_used", allowed_threads()},
                        {"load_average_1min_at_start", load_at_start.load_average_1min >= 0 ? nlohmann::json(load_at_start.load_average_1min) : nlohmann::json()},
                        {"load_average_1min_at_end", load_at_end.load_average_1min >= 0 ? nlohmann::json(load_at_end.load_average_1min) : nlohmann::json()}};
  model.add_summary(summary, solve_s);
  {
    std::ofstream out(folder.path("summary.json"));
    out << summary.dump(2) << "\n";
  }
  log.line(fmt::format("{}{}: deflection {:.6g} mm after {}", status, reason.empty() ? "" : " (" + reason + ")", deflection, model.log_steps(solve_s)));
  folder.commit();
  if (!o.quiet)
    fmt::print("{} {}: deflection {:.6g} mm, {}, {:.1f} s -> {}\n", model.needle_name(), status, deflection, model.print_steps(), solve_s,
               folder.final_path().string());
  if (status == "interrupted") throw Interrupted(interrupts.signal(), reason + fmt::format(" (what was written so far is in {})", o.out_dir));
  if (status != "finished" && o.throw_on_stop) throw SolverError(reason + fmt::format(" (what was written so far is in {})", o.out_dir));
}

}  // namespace needle
