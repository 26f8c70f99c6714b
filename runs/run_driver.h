#pragma once
// One run driver for `needle simulate` and `needle run`: the run folder (scene.json, run.log), the step loop
// with history records at the scene's interval, ParaView frames and progress, a solver stop caught with its
// reason, and summary.json with the entries every run has plus the model's own. What it runs is a RunModel:
// the needle alone (needle_alone_run.h) or the coupled insertion (insertion_run.h). Everything that can be
// wrong with the input is found while the model is built, before the run folder exists.
#include <Eigen/Dense>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "runs/run_folder.h"
#include "runs/scene.h"

namespace needle {

struct RunOptions {
  std::string out_dir;
  bool overwrite = false, quiet = false;
  bool throw_on_stop = true;  // false: a run the solver stopped returns normally (its summary says so)
  int threads = -1;           // -1: the scene's solver.threads
  std::string note;           // a line on how the scene was set up (e.g. where E came from): printed once the model is built, and logged
};

class RunModel {
 public:
  virtual ~RunModel() = default;
  virtual std::string needle_name() const = 0;
  virtual std::vector<std::string> setup_log() const = 0;  // run.log's lines on what was built
  virtual double end_time_ms() const = 0;
  virtual double time_ms() const = 0;
  virtual long steps() const = 0;
  virtual void step(double end_time_ms) = 0;  // SolverError stops the run with its reason
  virtual void open_outputs(const RunFolder& folder) = 0;  // history.csv and the model's other per-record files
  virtual void record() = 0;                               // a row of each, now
  virtual void frame(const RunFolder& folder) = 0;         // a ParaView frame, now
  virtual void close_outputs(const RunFolder& folder) = 0;  // the files closed, the .pvd series written
  virtual Eigen::Vector3d tip_displacement_mm() const = 0;  // tip point A's
  virtual Eigen::Vector3d drive_displacement_mm() const = 0;
  virtual double energy_balance_error() const = 0;
  virtual double max_energy_balance_error() const = 0;
  // The model's own summary entries, and its words on the run's steps for run.log and the terminal.
  virtual void add_summary(nlohmann::json& summary, double solve_s) const = 0;
  virtual std::string log_steps(double solve_s) const = 0;
  virtual std::string print_steps() const = 0;
};

// Builds the model (with the run's worker threads; InputError before anything is written) and runs it to its
// end into options.out_dir. SolverError after writing the folder if the solver stopped (unless !throw_on_stop).
void drive_run(const Scene& scene, const RunOptions& options, const std::function<std::unique_ptr<RunModel>()>& build);

}  // namespace needle
