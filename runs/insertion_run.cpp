#include "runs/insertion_run.h"

#include <algorithm>
#include <chrono>
#include <fmt/format.h>
#include <fstream>

#include "runs/json_file.h"
#include "runs/model_levels.h"
#include "runs/run_driver.h"
#include "runs/run_folder.h"
#include "runs/scene_needle.h"
#include "runs/scene_particles.h"
#include "core/input_error.h"
#include "mesher/particle_lattice.h"
#include "mesher/vtk_files.h"
#include "solver/insertion/groove_fill.h"
#include "solver/insertion/strain_probes.h"
#include "solver/insertion/coupled_insertion.h"
#include "solver/needle/needle_models.h"
#include "solver/separation/separation_models.h"
#include "core/parallel.h"
#include "core/solver_error.h"

#ifndef NEEDLE_DATA_DIR
#define NEEDLE_DATA_DIR "data"
#endif

namespace needle {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

// Broken bonds per particle.
Eigen::VectorXd broken_bonds(const SpgTissue& tissue) {
  Eigen::VectorXd count = Eigen::VectorXd::Zero(tissue.particles().size());
  for (const Bond& b : tissue.bonds().bonds)
    if (b.broken) {
      count[b.i] += 1;
      count[b.j] += 1;
    }
  return count;
}

// The particles pulled back into the needle's reference frame (as the contact does), and the tissue block's x range there.
struct PulledBackTissue {
  std::vector<Eigen::Vector3d> points;
  double min_x_mm = 0, max_x_mm = 0;
};

PulledBackTissue pulled_back_tissue(CoupledInsertion& run, const Scene& scene) {
  const double drive_x = run.needle().drive_displacement_mm().x();
  return {run.contact_model().pull_back(run.tissue().particles().position_mm, run.needle().positions_mm()),
          scene.tissue.entry_x_mm - drive_x, scene.tissue.entry_x_mm + scene.tissue.size_mm.x() - drive_x};
}

// The groove fill of the run's current state (groove_fill.h); empty without a groove.
GrooveFill run_groove_fill(CoupledInsertion& run, const SceneNeedle& needle, const Scene& scene) {
  if (!needle.groove) return {};
  const TissueParticles& p = run.tissue().particles();
  NeedleTissueContact& contact = run.contact_model();
  PulledBackTissue tissue = pulled_back_tissue(run, scene);
  GrooveFillInput in;
  in.groove = *needle.groove;
  in.radius_mm = needle.radius_mm;
  in.tissue_min_x_mm = tissue.min_x_mm;
  in.tissue_max_x_mm = tissue.max_x_mm;
  in.reference_points = std::move(tissue.points);
  in.spacing_mm = p.spacing_mm;
  in.touches_floor.assign(in.reference_points.size(), 0);
  const ContactSurface& surface = contact.surface();
  for (const auto& [particle, triangle] : contact.contacts())
    if (triangle >= 0 && surface.tag_names()[static_cast<size_t>(surface.triangle_tag(triangle))] == "groove_floor")
      in.touches_floor[static_cast<size_t>(particle)] = 1;
  return measure_groove_fill(in);
}

// The tissue's minimum principal strain where the paper's model shows it (strain_probes.h), at the run's current state.
StrainProbes run_strain_probes(CoupledInsertion& run, const SceneNeedle& needle, const Scene& scene) {
  const TissueParticles& p = run.tissue().particles();
  NeedleTissueContact& contact = run.contact_model();
  PulledBackTissue tissue = pulled_back_tissue(run, scene);
  StrainProbeInput in;
  in.reference_points = std::move(tissue.points);
  in.tissue_min_x_mm = tissue.min_x_mm;
  in.tissue_max_x_mm = tissue.max_x_mm;
  in.spacing_mm = p.spacing_mm;
  in.min_principal_strain.resize(p.elastic_left_cauchy_green.size());
  for (size_t i = 0; i < in.min_principal_strain.size(); ++i) in.min_principal_strain[i] = min_principal_log_strain(p.elastic_left_cauchy_green[i]);
  const ContactSurface& surface = contact.surface();
  in.contact_tag.assign(in.reference_points.size(), -1);
  for (const auto& [particle, triangle] : contact.contacts())
    if (triangle >= 0) in.contact_tag[static_cast<size_t>(particle)] = surface.triangle_tag(triangle);
  in.tag_names = surface.tag_names();
  in.tip_point = needle.tip_point;
  in.groove = needle.groove;
  in.radius_mm = needle.radius_mm;
  return probe_strains(in);
}

json strain_probes_json(const StrainProbes& probes, double insertion_mm, double deflection_mm) {
  auto region = [](const StrainRegion& r) {
    auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    return json{{"particles", r.particles}, {"median", number(r.median)}, {"p05", number(r.p05)}, {"min", number(r.min)}};
  };
  return {{"insertion_mm", insertion_mm},
          {"deflection_mm", deflection_mm},
          {"tip_top", region(probes.tip_top)},
          {"below_tip", region(probes.below_tip)},
          {"groove", region(probes.groove)}};
}

class InsertionOutput {
 public:
  InsertionOutput(const RunFolder& folder, const ContactSurface& surface, const std::vector<std::unique_ptr<SeparationModel>>& separations)
      : folder_(folder), surface_(surface) {
    history_.open(folder.path("history.csv"));
    history_ << "time_ms,insertion_mm,tip_dx_mm,tip_dy_mm,tip_dz_mm,deflection_mm,drive_force_x_N,drive_force_y_N,drive_force_z_N,"
                "contact_force_x_N,contact_force_y_N,contact_force_z_N,particles_in_contact,particles_inside,max_depth_mm,"
                "bonds_broken,tissue_kinetic_mJ,tissue_internal_mJ,needle_kinetic_mJ,needle_strain_mJ,drive_work_mJ,"
                "cannula_work_mJ,contact_work_mJ,penalty_energy_mJ,friction_dissipation_mJ,relinearisation_energy_mJ,energy_balance_error,"
                "coupling_step_ms,needle_steps,groove_fill,groove_floor_contact_fraction";
    for (const auto& separation : separations)
      for (const std::string& column : separation->history_columns()) history_ << "," << column;
    history_ << "\n";
    facets_.open(folder.path("facet_forces.csv"));
    facets_ << "time_ms,insertion_mm";
    for (const std::string& tag : surface.tag_names())
      if (tag != "symmetry")
        facets_ << fmt::format(",{0}_particles,{0}_normal_N,{0}_friction_N,{0}_fx_N,{0}_fy_N,{0}_fz_N", tag);
    facets_ << "\n";
  }

  void record(const CoupledInsertion& run, int tip, const GrooveFill& groove) {
    const NeedleModel& n = run.needle();
    const Eigen::RowVector3d u = n.positions_mm().row(tip) - n.mesh().X.row(tip);
    const Eigen::Vector3d drive = n.drive_displacement_mm(), reaction = n.drive_reaction_N();
    const ContactReport& c = run.contact();
    const InsertionEnergy& e = run.energy();
    history_ << fmt::format(
        "{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{},{},{:.6g},{},{:.9g},{:.9g},{:.9g},{:.9g},"
        "{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.6g},{:.6g},{},{:.4f},{:.4f}",
        run.time_ms(), drive.norm(), u.x(), u.y(), u.z(), u.y() - drive.y(), reaction.x(), reaction.y(), reaction.z(),
        c.force_on_needle_N.x(), c.force_on_needle_N.y(), c.force_on_needle_N.z(), c.particles_in_contact, c.particles_inside,
        c.max_depth_mm, run.bonds_broken(), e.tissue_kinetic_mJ, e.tissue_internal_mJ, e.needle_kinetic_mJ, e.needle_strain_mJ,
        e.drive_work_mJ, e.cannula_work_mJ, e.contact_work_mJ, e.penalty_energy_mJ, e.friction_dissipation_mJ, e.relinearisation_energy_mJ, e.balance_error(),
        run.last_step_ms(), run.needle_steps(), groove.groove_fill, groove.floor_contact_fraction);
    for (const auto& separation : run.separations())
      for (const std::string& value : separation->history_values()) history_ << "," << value;
    history_ << "\n";
    facets_ << fmt::format("{:.9g},{:.9g}", run.time_ms(), drive.norm());
    for (size_t k = 0; k < surface_.tag_names().size(); ++k) {
      if (surface_.tag_names()[k] == "symmetry") continue;
      const FacetContact& f = c.facets[k];
      facets_ << fmt::format(",{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}", f.particles, f.normal_N, f.friction_N, f.force_N.x(), f.force_N.y(),
                             f.force_N.z());
    }
    facets_ << "\n";
    history_.flush();  // a run killed from outside still leaves its history
    facets_.flush();
  }

  void frame(const CoupledInsertion& run) {
    const int index = static_cast<int>(needle_frames_.size());
    const std::string needle_name = fmt::format("frames/needle_{:04}.vtu", index);
    write_needle_vtu(folder_.path(needle_name).string(), run.needle());
    needle_frames_.emplace_back(run.time_ms(), needle_name);

    const TissueParticles& p = run.tissue().particles();
    const Eigen::Index np = p.size();
    Eigen::MatrixX3d x(np, 3), u(np, 3), v(np, 3);
    Eigen::VectorXd plastic(np), effective(np), min_principal(np), mises(np), contact(np);
    const std::vector<std::uint8_t> in_contact = run.contact_model().in_contact();
    for (Eigen::Index i = 0; i < np; ++i) {
      const size_t s = static_cast<size_t>(i);
      x.row(i) = p.position_mm[s].transpose();
      u.row(i) = (p.position_mm[s] - p.initial_mm[s]).transpose();
      v.row(i) = p.velocity_mm_per_ms[s].transpose();
      plastic[i] = p.plastic_strain[s];
      effective[i] = p.effective_strain[s];
      min_principal[i] = min_principal_log_strain(p.elastic_left_cauchy_green[s]);
      const Mat3d dev = p.stress_MPa[s] - p.stress_MPa[s].trace() / 3 * Mat3d::Identity();
      mises[i] = std::sqrt(1.5 * dev.squaredNorm());
      contact[i] = in_contact[s];
    }
    const std::string tissue_name = fmt::format("frames/tissue_{:04}.vtp", index);
    write_vtp(folder_.path(tissue_name).string(), x,
              {{"displacement_mm", u}, {"velocity_m_per_s", v}, {"plastic_strain", plastic}, {"effective_strain", effective},
               {"min_principal_strain", min_principal}, {"von_mises_MPa", mises},
               {"broken_bonds", broken_bonds(run.tissue())}, {"in_contact", contact}},
              VtkEncoding::binary);
    tissue_frames_.emplace_back(run.time_ms(), tissue_name);
  }

  void finish() {
    history_.close();
    facets_.close();
    write_pvd(folder_.path("needle.pvd"), needle_frames_);
    write_pvd(folder_.path("tissue.pvd"), tissue_frames_);
  }

 private:
  const RunFolder& folder_;
  const ContactSurface& surface_;
  std::ofstream history_, facets_;
  std::vector<std::pair<double, std::string>> needle_frames_, tissue_frames_;
};

}  // namespace

std::string default_calibration_file(const std::string& model_level) {
  // A level's own calibration; a custom combination takes the default (fast) level's.
  const ModelLevel* level = find_model_level(model_level);
  return std::string(NEEDLE_DATA_DIR) + "/paper/" + (level ? level->calibration_file : find_model_level(kDefaultModelLevel)->calibration_file);
}

double calibrated_E(const std::string& path) {
  const json j = read_json_file(path, "calibration");
  NEEDLE_REQUIRE(j.contains("tissue_E_MPa") && j["tissue_E_MPa"].is_number() && j["tissue_E_MPa"].get<double>() > 0,
                 fmt::format("{}: tissue_E_MPa must be a positive number", path));
  return j["tissue_E_MPa"].get<double>();
}

Scene default_run_scene() {
  Scene s = parse_scene("{}", "(needle run defaults)");
  s.tissue.enabled = true;
  s.needle.mesh.size_mm = 0.4;
  s.solver.mass_scaling_dt_ms = 5e-6;
  s.tissue.path_refinement = 2;  // 0.2 mm particles within 1.2 mm of the path: the tip's bevels see tissue
  apply_model_level(s, kDefaultModelLevel, "the run defaults");
  return s;
}

namespace {

// The coupled insertion of a scene as the run driver runs it (run_driver.h).
class InsertionRunModel : public RunModel {
 public:
  explicit InsertionRunModel(const Scene& scene) : scene_(scene) {
    NEEDLE_REQUIRE(scene.tissue.enabled, "run_insertion needs a scene with tissue.enabled");
    check_model_combination(scene);
    const auto start = Clock::now();
    built_ = build_scene_needle(scene.needle);
    const bool mass_scaled = needle_model(scene.needle.model).mass_scaled;  // a rigid needle takes any step: no mass scaling
    needle_ = std::make_unique<FeNeedle>(built_.mesh, scene.needle.material, mass_scaled ? scene.solver.mass_scaling_dt_ms : 0.0);
    ContactSurfaceOptions surface_options;
    surface_options.voxel_mm = scene.tissue.contact.voxel_mm;
    surface_ = std::make_unique<ContactSurface>(needle_->mesh(), surface_options);
    particles_ = scene_particles(scene);
    tissue_ = std::make_unique<SpgTissue>(particles_, scene.tissue.material, scene.tissue.spg);
    CuttingOptions cutting = scene.tissue.cutting;
    cutting.facets = built_.tip_facets;
    const bool ground_tip = !built_.tip_facets.empty();  // a plain rod's end is cut square; a mesh file names no facets
    NEEDLE_REQUIRE(!cutting.enabled() || ground_tip,
                   "a cutting pressure needs a needle with tip facets: a ground tip from a preset, d_a or a recipe (not a plain rod or a mesh file)");
    NEEDLE_REQUIRE(!scene.tissue.separation.crack.enabled() || ground_tip,
                   "a crack from the tip point needs a needle with a ground tip point: a preset, d_a or a recipe (not a plain rod or a mesh file)");
    // A plain rod's end is cut square and a mesh file names no tip point: neither has a lip below A to release.
    SeparationOptions separation = scene.tissue.separation;
    if (!ground_tip) separation.lip.mode = LipReleaseMode::off;
    std::vector<std::unique_ptr<SeparationModel>> separations = make_separation_models(separation, *surface_);
    setup_s_ = std::chrono::duration<double>(Clock::now() - start).count();
    NeedleDynamicsOptions dynamics = scene_dynamics_options(scene);
    // The implicit needle's step by default: about half the tissue's stable step at the start, a whole fraction
    // of the history interval (the run lands on each record); the coupling steps are whole eighths of it as the
    // tissue's step shrinks (the gel compresses), so the needle factors a few times a run.
    if (dynamics.implicit_step_ms <= 0) {
      const double interval = scene.output.history_interval_ms;
      dynamics.implicit_step_ms = interval / std::ceil(interval / (0.5 * tissue_->stable_time_step_ms()));
    }
    needle_model_ = make_needle_model(scene.needle.model, {*needle_, driven_base_supports(needle_->mesh(), scene.motion, scene.direction),
                                                           scene.cannula.enabled ? std::optional<CannulaOptions>(scene.cannula) : std::nullopt,
                                                           dynamics});
    // The tissue's mass scaling target unless a step is given: a quarter of the implicit needle's step (the
    // coupling steps are whole eighths of it), for an explicit needle half the tissue's first. The quarter is its
    // measured error at 30 mm: 0.10 mm on HMB, none on SB, where the needle's whole step left 0.32 and 0.05 mm
    // (the crushed lip's particles made hundreds of times heavier; docs/insertion.md, the mass scaling).
    constexpr double kMassScalingTargetPerNeedleStep = 0.25;
    CouplingOptions coupling = scene.solver.coupling;
    if (scene.solver.tissue_mass_scaling || scene.solver.tissue_mass_scaling_dt_ms > 0)
      coupling.tissue_mass_scaling_dt_ms = scene.solver.tissue_mass_scaling_dt_ms > 0 ? scene.solver.tissue_mass_scaling_dt_ms
                                           : needle_model(scene.needle.model).takes_coupling_step
                                               ? kMassScalingTargetPerNeedleStep * dynamics.implicit_step_ms
                                                                              : 0.5 * tissue_->stable_time_step_ms();
    run_ = std::make_unique<CoupledInsertion>(*needle_model_, *tissue_, *surface_, scene.tissue.contact, std::move(separations), coupling,
                                              cutting);
    tip_ = nearest_node(needle_->mesh(), built_.tip_point);
  }

  std::string needle_name() const override { return built_.name; }
  std::vector<std::string> setup_log() const override {
    const FeNeedle& n = *needle_;
    const ContactSurface& surface = *surface_;
    return {fmt::format("needle {}: {} T{} elements, {} nodes, meshed in {:.2f} s", built_.name, built_.mesh.num_tets(),
                        built_.mesh.order == 2 ? 10 : 4, built_.mesh.num_nodes(), built_.mesh_seconds),
            fmt::format("model {}: {} needle, {} contact, {} kernel supports", model_level_of(scene_), needle_model_->name(),
                        run_->contact_model().law(), support_shape_name(scene_.tissue.spg.support)),
            fmt::format("needle stable step {:.4g} ms (unscaled {:.4g} ms); added mass {:.3g} % in {} elements", n.stable_time_step_ms(),
                        n.unscaled_time_step_ms(), 100 * n.added_mass_g() / n.physical_mass_g(), n.mass_scaled_elements()),
            fmt::format("contact surface: {} triangles, level set {} voxels of {} mm ({:.1f} MiB) built in {:.2f} s", surface.num_triangles(),
                        surface.level_set().active_voxels(), surface.level_set().voxel_mm(), surface.level_set().memory_bytes() / 1048576.0,
                        surface.level_set().build_seconds()),
            fmt::format("tissue: {} particles at {:.3g} mm ({:.3g} mm near the path), {} bonds; set-up {:.2f} s", particles_.num_particles(),
                        scene_.tissue.spacing_mm, particles_.spacing_mm.minCoeff(), tissue_->bonds().bonds.size(), setup_s_),
            fmt::format("run to {:.6g} ms: needle step {:.4g} ms, first coupling step {:.4g} ms (tissue {:.4g}, contact {:.4g}){}", end_time_ms(),
                        needle_model_->time_step_ms(), run_->tissue_dynamics().time_step_ms(), tissue_->stable_time_step_ms(),
                        run_->contact_model().max_time_step_ms(scene_.solver.coupling.contact_courant),
                        run_->tissue_dynamics().mass_scaling()
                            ? fmt::format("; particles whose own step falls below {:.4g} ms get mass (tissue mass scaling)",
                                          run_->tissue_dynamics().mass_scaling()->target_dt_ms())
                            : std::string())};
  }
  double end_time_ms() const override { return scene_.motion.end_time_ms(); }
  double time_ms() const override { return run_->time_ms(); }
  long steps() const override { return run_->steps(); }
  void step(double end_time_ms) override { run_->step(end_time_ms); }
  void open_outputs(const RunFolder& folder) override { output_ = std::make_unique<InsertionOutput>(folder, *surface_, run_->separations()); }
  void record() override {
    output_->record(*run_, tip_, run_groove_fill(*run_, built_, scene_));
    // The strains where the paper shows them at L = 4.8 mm: at the first record past it.
    const double insertion_mm = needle_model_->drive_displacement_mm().norm();
    if (early_probes_.is_null() && insertion_mm >= kEarlyProbeInsertionMm)
      early_probes_ = strain_probes_json(run_strain_probes(*run_, built_, scene_), insertion_mm, deflection_mm());
  }
  void frame(const RunFolder&) override { output_->frame(*run_); }
  void close_outputs(const RunFolder&) override { output_->finish(); }
  Eigen::Vector3d tip_displacement_mm() const override {
    return (needle_model_->positions_mm().row(tip_) - needle_->mesh().X.row(tip_)).transpose();
  }
  Eigen::Vector3d drive_displacement_mm() const override { return needle_model_->drive_displacement_mm(); }
  double energy_balance_error() const override { return run_->energy().balance_error(); }
  double max_energy_balance_error() const override { return run_->max_energy_error(); }

  void add_summary(json& summary, double) const override {
    const InsertionEnergy& e = run_->energy();
    const GrooveFill groove = run_groove_fill(*run_, built_, scene_);
    summary["needle_steps"] = run_->needle_steps();
    summary["needle_model"] = needle_model_->name();
    summary["contact_law"] = run_->contact_model().law();
    summary["model_level"] = model_level_of(scene_);
    summary["subcycling"] = scene_.solver.coupling.subcycling;
    summary["energy_mJ"] = {{"drive_work", e.drive_work_mJ}, {"tissue_internal", e.tissue_internal_mJ}, {"tissue_kinetic", e.tissue_kinetic_mJ},
                            {"needle_kinetic", e.needle_kinetic_mJ}, {"needle_strain", e.needle_strain_mJ}, {"contact_work", e.contact_work_mJ},
                            {"penalty", e.penalty_energy_mJ}, {"friction_dissipation", e.friction_dissipation_mJ}, {"cannula_work", e.cannula_work_mJ}};
    summary["max_penetration_mm"] = run_->max_depth_mm();
    summary["particles_inside"] = run_->contact().particles_inside;
    summary["max_particles_inside"] = run_->max_particles_inside();
    summary["particles"] = particles_.num_particles();
    summary["bonds_broken"] = run_->bonds_broken();
    summary["groove"] = {{"groove_fill", groove.groove_fill},
                         {"floor_contact_fraction", groove.floor_contact_fraction},
                         {"mean_gap_mm", groove.mean_gap_mm},
                         {"length_in_tissue_mm", groove.length_in_tissue_mm},
                         {"particles_in_groove", groove.particles_in_groove},
                         {"definition", "docs/insertion.md#groove-fill: mean over the groove's length in tissue of the filled share of its depth "
                                        "(tissue's lowest edge to the rod's top over floor to top), in the needle's own frame"}};
    summary["mesh"] = {{"order", needle_->mesh().order}, {"elements", needle_->num_elements()}, {"nodes", needle_->num_nodes()}};
    needle_model_->add_summary(summary);
    if (const TissueMassScaling* scaling = run_->tissue_dynamics().mass_scaling()) {
      const MassScalingReport& r = scaling->report();
      summary["tissue_mass_scaling"] = {{"target_dt_ms", scaling->target_dt_ms()},
                                        {"max_added_mass_percent", 100 * r.max_added_mass_g / scaling->physical_mass_g()},
                                        {"added_mass_percent_at_end", 100 * r.added_mass_g / scaling->physical_mass_g()},
                                        {"max_mass_ratio", r.max_ratio},
                                        {"max_added_mass_percent_crushed", 100 * r.max_added_mass_crushed_g / scaling->physical_mass_g()},
                                        {"max_mass_ratio_crushed", r.max_ratio_crushed},
                                        {"scaled_particles_at_end", r.scaled_particles},
                                        {"kinetic_energy_added_mJ", r.energy_mJ}};
    }
    if (const TissueRateLevels* levels = run_->tissue_dynamics().rate_levels())
      summary["tissue_rate_levels"] = {{"max_level", levels->max_level()},
                                       {"needle_margin_mm", scene_.solver.coupling.tissue_rate_needle_margin_mm},
                                       {"safety", levels->safety()},
                                       {"mean_point_update_share", levels->mean_point_update_share()},
                                       {"last_point_level_shares", levels->last_point_level_shares()}};
    summary["strain_probes"] = {{"definition", "solver/insertion/strain_probes.h: the smallest principal elastic Hencky strain of the particles "
                                               "touching the top facets (tip_top), touching the tip within 2 mm behind A and no higher than A "
                                               "(below_tip), and inside the groove (groove); median, 5th percentile and minimum"}};
    if (!early_probes_.is_null()) summary["strain_probes"]["early"] = early_probes_;
    summary["strain_probes"]["end"] =
        strain_probes_json(run_strain_probes(*run_, built_, scene_), needle_model_->drive_displacement_mm().norm(), deflection_mm());
    if (run_->cutting()) run_->cutting()->add_summary(summary);
    for (const auto& separation : run_->separations()) separation->add_summary(summary, run_->tissue());
  }
  std::string log_steps(double solve_s) const override {
    return fmt::format("{} coupling steps and {} needle steps in {:.2f} s, energy balance error {:.3g}, max penetration {:.3g} mm, {} particles "
                       "inside at the end",
                       run_->steps(), run_->needle_steps(), solve_s, run_->energy().balance_error(), run_->max_depth_mm(),
                       run_->contact().particles_inside);
  }
  std::string print_steps() const override { return fmt::format("{} steps ({} needle steps)", run_->steps(), run_->needle_steps()); }

 private:
  const Scene& scene_;
  SceneNeedle built_;
  std::unique_ptr<FeNeedle> needle_;
  std::unique_ptr<ContactSurface> surface_;
  ParticleSet particles_;
  std::unique_ptr<SpgTissue> tissue_;
  std::unique_ptr<NeedleModel> needle_model_;
  std::unique_ptr<CoupledInsertion> run_;
  int tip_ = 0;
  double setup_s_ = 0;
  std::unique_ptr<InsertionOutput> output_;
  static constexpr double kEarlyProbeInsertionMm = 4.8;  // the paper's first look (its Figs. 6 and 7)
  json early_probes_;  // null until the insertion passes kEarlyProbeInsertionMm

  double deflection_mm() const { return tip_displacement_mm().y() - drive_displacement_mm().y(); }
};

}  // namespace

void run_insertion(const Scene& scene, const RunOptions& o) {
  // Everything that can be wrong with the input is found while the model is built, before the run folder exists.
  drive_run(scene, o, [&scene] { return std::make_unique<InsertionRunModel>(scene); });
}

bool folder_holds_run_of(const Scene& scene, const std::string& folder_name) {
  const std::filesystem::path folder(folder_name);
  std::ifstream summary(folder / "summary.json"), stored(folder / "scene.json");
  if (!summary.good() || !stored.good()) return false;
  // The worker threads are left out of the comparison: every kernel is a gather (core/parallel.h), so a run's
  // results do not depend on them (a test runs the same scene on one and two threads and compares the histories).
  auto without_threads = [](json scene_json) {
    if (scene_json.contains("solver") && scene_json["solver"].is_object()) scene_json["solver"].erase("threads");
    return scene_json;
  };
  try {
    // A run stopped by Ctrl-C holds what it had so far, not a result: it runs again.
    if (json::parse(summary).value("status", std::string()) == "interrupted") return false;
    return without_threads(json::parse(stored)) == without_threads(json::parse(scene_to_json(scene).dump()));
  } catch (const json::exception&) {
    return false;  // an unreadable folder holds no run
  }
}

bool run_insertion_unless_done(const Scene& scene, const RunOptions& options) {
  const bool done = folder_holds_run_of(scene, options.out_dir);
  if (!done) run_insertion(scene, options);
  return done;
}

}  // namespace needle
