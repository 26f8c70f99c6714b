#include "runs/needle_alone_run.h"

#include <algorithm>
#include <fmt/format.h>
#include <fstream>
#include <memory>

#include "runs/scene_needle.h"
#include "core/parallel.h"
#include "core/input_error.h"
#include "solver/needle/needle_dynamics.h"
#include "solver/needle/needle_models.h"

namespace needle {
namespace {

using Clock = std::chrono::steady_clock;

class NeedleAloneModel : public RunModel {
 public:
  explicit NeedleAloneModel(const Scene& scene) : scene_(scene) {
    // It drives the explicit FE needle itself: another model asked for is refused, not replaced (issue 49).
    NEEDLE_REQUIRE(needle_model(scene.needle.model).runs_alone,
                   fmt::format("needle.model {}: a needle-alone run (tissue.enabled false) runs the explicit FE needle only; give "
                               "needle.model fe, or a tissue to insert into",
                               scene.needle.model));
    built_ = build_scene_needle(scene.needle);
    needle_ = std::make_unique<FeNeedle>(built_.mesh, scene.needle.material, scene.solver.mass_scaling_dt_ms);
    run_ = std::make_unique<NeedleDynamics>(*needle_, driven_base_supports(needle_->mesh(), scene.motion, scene.direction),
                                            scene.cannula.enabled ? std::optional<CannulaOptions>(scene.cannula) : std::nullopt,
                                            scene_dynamics_options(scene));
    tip_ = nearest_node(needle_->mesh(), built_.tip_point);
  }

  std::string needle_name() const override { return built_.name; }
  std::vector<std::string> setup_log() const override {
    const FeNeedle& n = *needle_;
    return {fmt::format("needle {}: {} T{} elements, {} nodes, meshed in {:.2f} s", built_.name, built_.mesh.num_tets(),
                        built_.mesh.order == 2 ? 10 : 4, built_.mesh.num_nodes(), built_.mesh_seconds),
            fmt::format("stable step {:.4g} ms (unscaled {:.4g} ms); mass {:.5g} g, added by mass scaling {:.3g} % in {} elements",
                        n.stable_time_step_ms(), n.unscaled_time_step_ms(), n.physical_mass_g(), 100 * n.added_mass_g() / n.physical_mass_g(),
                        n.mass_scaled_elements()),
            fmt::format("run to {:.6g} ms with dt {:.4g} ms: about {:.0f} steps", end_time_ms(), run_->time_step_ms(),
                        end_time_ms() / run_->time_step_ms())};
  }
  double end_time_ms() const override { return scene_.motion.end_time_ms(); }
  double time_ms() const override { return run_->time_ms(); }
  long steps() const override { return run_->steps(); }
  void step(double end_time_ms) override {
    run_->step(end_time_ms);
    if (std::abs(run_->energy().drive_work_mJ) > 1e-6) max_balance_ = std::max(max_balance_, run_->energy().balance_error());
    max_penetration_ = std::max(max_penetration_, run_->cannula_contact().max_penetration_mm);
    max_contacts_ = std::max(max_contacts_, run_->cannula_contact().nodes_in_contact);
  }
  void open_outputs(const RunFolder& folder) override {
    history_.open(folder.path("history.csv"));
    history_ << "time_ms,insertion_mm,tip_dx_mm,tip_dy_mm,tip_dz_mm,deflection_mm,base_reaction_x_N,base_reaction_y_N,"
                "base_reaction_z_N,kinetic_mJ,strain_mJ,drive_work_mJ,cannula_work_mJ,energy_balance_error,"
                "cannula_contact_nodes,cannula_max_penetration_mm,cannula_force_y_N\n";
  }
  void record() override {
    const Eigen::Vector3d u = tip_displacement_mm(), drive = run_->drive_displacement_mm(), reaction = run_->drive_reaction_N();
    const NeedleEnergy& e = run_->energy();
    const CannulaContact& c = run_->cannula_contact();
    history_ << fmt::format("{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.6g},{},{:.6g},{:.6g}\n",
                            run_->time_ms(), drive.norm(), u.x(), u.y(), u.z(), u.y() - drive.y(), reaction.x(), reaction.y(), reaction.z(),
                            e.kinetic_mJ, e.strain_mJ, e.drive_work_mJ, e.cannula_work_mJ, e.balance_error(), c.nodes_in_contact,
                            c.max_penetration_mm, c.force_N.y());
    history_.flush();  // a run killed from outside still leaves its history
  }
  void frame(const RunFolder& folder) override {
    const std::string name = fmt::format("frames/needle_{:04}.vtu", frames_.size());
    write_needle_vtu(folder.path(name).string(), *run_);
    frames_.emplace_back(run_->time_ms(), name);
  }
  void close_outputs(const RunFolder& folder) override {
    history_.close();
    write_pvd(folder.path("needle.pvd"), frames_);
  }
  Eigen::Vector3d tip_displacement_mm() const override { return (run_->positions_mm().row(tip_) - needle_->mesh().X.row(tip_)).transpose(); }
  Eigen::Vector3d drive_displacement_mm() const override { return run_->drive_displacement_mm(); }
  double energy_balance_error() const override { return run_->energy().balance_error(); }
  double max_energy_balance_error() const override { return max_balance_; }
  void add_summary(nlohmann::json& summary, double solve_s) const override {
    const FeNeedle& n = *needle_;
    summary["time_step_ms"] = run_->time_step_ms();
    summary["unscaled_time_step_ms"] = n.unscaled_time_step_ms();
    summary["mass_g"] = n.physical_mass_g();
    summary["added_mass_percent"] = 100 * n.added_mass_g() / n.physical_mass_g();
    summary["max_cannula_penetration_mm"] = max_penetration_;
    summary["max_cannula_contact_nodes"] = max_contacts_;
    summary["steps_per_s"] = run_->steps() / std::max(solve_s, 1e-9);
    summary["mesh"] = {{"order", n.mesh().order}, {"elements", n.num_elements()}, {"nodes", n.num_nodes()},
                       {"straightened_tets", n.mesh().straightened_tets}};
  }
  std::string log_steps(double solve_s) const override {
    return fmt::format("{} steps in {:.2f} s ({:.0f} steps/s), energy balance error {:.3g}", run_->steps(), solve_s,
                       run_->steps() / std::max(solve_s, 1e-9), run_->energy().balance_error());
  }
  std::string print_steps() const override { return fmt::format("{} steps", run_->steps()); }

 private:
  const Scene& scene_;
  SceneNeedle built_;
  std::unique_ptr<FeNeedle> needle_;
  std::unique_ptr<NeedleDynamics> run_;
  int tip_ = 0;
  double max_balance_ = 0, max_penetration_ = 0;
  int max_contacts_ = 0;
  std::ofstream history_;
  std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace

void run_needle_alone(const Scene& scene, const RunOptions& o) {
  // Everything that can be wrong with the input is found while the model is built, before the run folder exists.
  drive_run(scene, o, [&scene] { return std::make_unique<NeedleAloneModel>(scene); });
}

}  // namespace needle
