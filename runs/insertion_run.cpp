#include "runs/insertion_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <fstream>

#include "runs/insertion_measures.h"
#include "runs/insertion_output.h"
#include "runs/model_levels.h"
#include "runs/run_driver.h"
#include "runs/run_folder.h"
#include "runs/sample_picture.h"
#include "runs/scene_needle.h"
#include "runs/scene_particles.h"
#include "core/input_error.h"
#include "mesher/particle_lattice.h"
#include "solver/insertion/cannula_firing.h"
#include "solver/needle/held_needle.h"
#include "solver/insertion/coupled_insertion.h"
#include "solver/needle/needle_models.h"
#include "solver/separation/cannula_edge_cut.h"
#include "solver/separation/separation_models.h"

namespace needle {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

// The fired cannula's tube: the scene cannula's bore and outer radius.
CannulaTube firing_tube(const Scene& scene, double rod_radius_mm) {
  return {scene.cannula.inner_radius_mm(), 0.5 * scene.cannula.outer_diameter_mm, scene.cannula_firing.edge_taper_mm, rod_radius_mm};
}

// The fired cannula's stroke in the needle's reference frame (solver/insertion/cannula_firing.h): from the cannula's
// front at rest (the scene cannula's front, carried back by the travel), or lead_in_mm behind the groove's back wall if
// that is farther forward, to the groove's front wall or the throw; it starts moving after the travel, its hold and
// the dwell.
CannulaStroke firing_stroke(const Scene& scene, const GrooveBox& groove) {
  const CannulaFiringOptions& f = scene.cannula_firing;
  NEEDLE_REQUIRE(scene.direction.normalized().isApprox(Eigen::Vector3d::UnitX(), 1e-12),
                 "cannula.firing: the cannula is fired along the needle's axis, x: it needs motion.direction [1, 0, 0]");
  const double rest_front_x = scene.cannula.front_x_mm - scene.motion.travel_mm;
  CannulaStroke stroke;
  stroke.speed_mm_per_ms = f.speed_mm_per_ms;
  stroke.start_time_ms = scene.motion.end_time_ms() + f.dwell_ms;
  stroke.stop_x_mm = std::isnan(f.throw_mm) ? groove.front_x_mm : rest_front_x + f.throw_mm;
  NEEDLE_REQUIRE(stroke.stop_x_mm > groove.back_x_mm,
                 fmt::format("cannula.firing.throw_mm {:g} mm stops the cannula's front {:.3g} mm behind the groove's back wall: it "
                             "would take no tissue (the groove spans {:.3g} to {:.3g} mm from the cannula's front at rest)",
                             f.throw_mm, groove.back_x_mm - stroke.stop_x_mm, groove.back_x_mm - rest_front_x,
                             groove.front_x_mm - rest_front_x));
  stroke.start_x_mm = std::min(stroke.stop_x_mm, std::max(rest_front_x, groove.back_x_mm - f.lead_in_mm));
  return stroke;
}

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
    if (scene.cannula_firing.enabled) {
      NEEDLE_REQUIRE(built_.groove, "cannula.firing takes the tissue in the needle's groove: it needs a needle with one (a preset, d_a or a "
                                    "recipe with a groove; not a plain rod or a mesh file)");
      firing_ = std::make_unique<CannulaFiring>(firing_tube(scene, built_.radius_mm), firing_stroke(scene, *built_.groove), NeedleAxisFrame(built_.mesh.X));
      separations.push_back(std::make_unique<CannulaEdgeCut>(*firing_));
    }
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
    // With a fired cannula the needle is held still from the insertion's end (held_needle.h): the device stops it.
    if (scene.cannula_firing.enabled) needle_model_ = std::make_unique<HeldNeedle>(std::move(needle_model_), scene.motion.end_time_ms());
    // The tissue's mass scaling target unless a step is given: half the implicit needle's step (the coupling
    // steps are whole eighths of it), for an explicit needle half the tissue's first. With only the lip's top crushed
    // (0.45 mm) the half step moves SB, LMB and AMB by under 0.01 mm against the quarter, with 32-48 % fewer steps, and
    // HMB by +0.095 mm, which the crushed depth's fit on HMB takes up (docs/notebook/multirate.md, the mass scaling's
    // target; with the whole lip crushed the needle's whole step left HMB 0.32 mm high: docs/insertion.md).
    constexpr double kMassScalingTargetPerNeedleStep = 0.5;
    CouplingOptions coupling = scene.solver.coupling;
    if (scene.solver.tissue_mass_scaling || scene.solver.tissue_mass_scaling_dt_ms > 0)
      coupling.tissue_mass_scaling_dt_ms = scene.solver.tissue_mass_scaling_dt_ms > 0 ? scene.solver.tissue_mass_scaling_dt_ms
                                           : needle_model(scene.needle.model).takes_coupling_step
                                               ? kMassScalingTargetPerNeedleStep * dynamics.implicit_step_ms
                                                                              : 0.5 * tissue_->stable_time_step_ms();
    run_ = std::make_unique<CoupledInsertion>(*needle_model_, *tissue_, *surface_, scene.tissue.contact, std::move(separations), coupling,
                                              cutting);
    if (firing_) run_->fire_cannula(firing_.get());
    tip_ = nearest_node(needle_->mesh(), built_.tip_point);
  }

  std::string needle_name() const override { return built_.name; }
  std::vector<std::string> setup_log() const override {
    const FeNeedle& n = *needle_;
    const ContactSurface& surface = *surface_;
    std::vector<std::string> lines = {fmt::format("needle {}: {} T{} elements, {} nodes, meshed in {:.2f} s", built_.name, built_.mesh.num_tets(),
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
    if (firing_) lines.push_back(firing_log());
    return lines;
  }
  std::string firing_log() const {
    const CannulaStroke& s = firing_->stroke();
    return fmt::format("cannula fired at {:.6g} ms at {:g} m/s, its front from {:.4g} to {:.4g} mm in the needle's frame (the groove: {:.4g} to "
                       "{:.4g} mm), until {:.6g} ms; bore {:.4g} mm, outer radius {:.4g} mm, the edge cuts along {:.4g} mm",
                       s.start_time_ms, s.speed_mm_per_ms, s.start_x_mm, s.stop_x_mm, built_.groove->back_x_mm, built_.groove->front_x_mm,
                       s.end_time_ms(), firing_->tube().inner_radius_mm, firing_->tube().outer_radius_mm, firing_->tube().mid_radius_mm());
  }
  // With a fired cannula the run goes on past the insertion to the stroke's end.
  double end_time_ms() const override { return firing_ ? firing_->stroke().end_time_ms() : scene_.motion.end_time_ms(); }
  double time_ms() const override { return run_->time_ms(); }
  long steps() const override { return run_->steps(); }
  void step(double end_time_ms) override {
    if (!firing_) return run_->step(end_time_ms);
    // The insertion's end is landed on: its deflection and groove are what the cannula's firing leaves as they were.
    const double insertion_end = scene_.motion.end_time_ms();
    run_->step(time_ms() < insertion_end - 1e-12 ? std::min(end_time_ms, insertion_end) : end_time_ms);
    if (!at_insertion_end_ && time_ms() >= insertion_end - 1e-12) {
      at_insertion_end_ = InsertionEnd{tip_displacement_now(), needle_model_->drive_displacement_mm(), run_groove_fill(*run_, built_, scene_),
                                       strain_probes_json(run_strain_probes(*run_, built_, scene_), needle_model_->drive_displacement_mm().norm(),
                                                          deflection_now())};
      // A history and facet-force row at the insertion's end, the instant its deflection is read (the run without the
      // firing ends on one): the report's loads and curves stop there (studies/paper_report.cpp). Written before the
      // masses are retargeted below, which the contact's forces (impulses over the step) are read with.
      if (output_) {
        output_->record(*run_, tip_, at_insertion_end_->groove);
        insertion_end_row_ms_ = time_ms();
      }
      // The held needle takes no coupling: the tissue steps at the firing's own mass-scaled step.
      if (const TissueMassScaling* scaling = run_->tissue_dynamics().mass_scaling()) {
        const double target = scene_.cannula_firing.tissue_mass_scaling_dt_ms;
        insertion_mass_scaling_dt_ms_ = scaling->target_dt_ms();
        run_->tissue_dynamics().retarget_mass_scaling(target > 0 ? target : CannulaFiringOptions::kMassScalingGrowth * scaling->target_dt_ms());
      }
    }
  }
  void open_outputs(const RunFolder& folder) override { output_ = std::make_unique<InsertionOutput>(folder, *surface_, run_->separations()); }
  void record() override {
    if (time_ms() != insertion_end_row_ms_) output_->record(*run_, tip_, run_groove_fill(*run_, built_, scene_));  // not twice
    // Over the stroke, which particles the contact listed on the groove floor (the tissue cut free may lift off it by the
    // stop): the sample's floor_length_during_stroke_mm, beside the contact's list at the stop.
    if (firing_ && firing_->active(time_ms())) {
      const std::vector<std::uint8_t> now = groove_floor_contacts(*run_);
      if (touched_floor_.empty()) touched_floor_.assign(now.size(), 0);
      for (size_t i = 0; i < now.size(); ++i) touched_floor_[i] |= now[i];
    }
    // The strains where the paper shows them at L = 4.8 mm: at the first record past it.
    const double insertion_mm = needle_model_->drive_displacement_mm().norm();
    if (early_probes_.is_null() && insertion_mm >= kEarlyProbeInsertionMm)
      early_probes_ = strain_probes_json(run_strain_probes(*run_, built_, scene_), insertion_mm, deflection_mm());
  }
  void frame(const RunFolder&) override { output_->frame(*run_); }
  void close_outputs(const RunFolder& folder) override {
    output_->finish();
    if (!firing_) return;
    // The sample as the stroke leaves it (I_s by the floor's nearest layer; beside it, the contact's list of particles on
    // the floor at the stop and at any record during the stroke), and its picture.
    const std::vector<std::uint8_t> on_floor = groove_floor_contacts(*run_);
    sample_ = run_tissue_sample(*run_, built_, *firing_, on_floor);
    sample_touched_during_stroke_ = run_tissue_sample(*run_, built_, *firing_, touched_floor_.empty() ? on_floor : touched_floor_);
    SamplePictureInput picture{firing_->reference_points(run_->tissue().particles().position_mm, needle_model_->positions_mm()), *sample_,
                               *built_.groove, built_.radius_mm, firing_->tube()};
    write_png(draw_sample_picture(picture), folder.path("sample.png").string());
  }
  // With a fired cannula, the tip's and the drive's at the insertion's end (the deflection the firing leaves alone).
  Eigen::Vector3d tip_displacement_mm() const override { return at_insertion_end_ ? at_insertion_end_->tip_mm : tip_displacement_now(); }
  Eigen::Vector3d drive_displacement_mm() const override {
    return at_insertion_end_ ? at_insertion_end_->drive_mm : needle_model_->drive_displacement_mm();
  }
  Eigen::Vector3d tip_displacement_now() const { return (needle_model_->positions_mm().row(tip_) - needle_->mesh().X.row(tip_)).transpose(); }
  double deflection_now() const { return tip_displacement_now().y() - needle_model_->drive_displacement_mm().y(); }
  double energy_balance_error() const override { return run_->energy().balance_error(); }
  double max_energy_balance_error() const override { return run_->max_energy_error(); }

  void add_summary(json& summary, double) const override {
    const InsertionEnergy& e = run_->energy();
    // The groove at the insertion's end (with a fired cannula, before it: the sample is its own entry).
    const GrooveFill groove = at_insertion_end_ ? at_insertion_end_->groove : run_groove_fill(*run_, built_, scene_);
    summary["needle_steps"] = run_->needle_steps();
    summary["needle_spans_ahead"] = run_->needle_spans_ahead();  // taken beside the tissue's update (solver.needle_ahead)
    // How many coupling steps each limit set (solver/insertion/coupled_insertion.h: StepLimit).
    json limits = json::object();
    for (int k = 0; k < kStepLimits; ++k) limits[step_limit_name(static_cast<StepLimit>(k))] = run_->step_limits()[static_cast<size_t>(k)];
    summary["coupling_step_limits"] = limits;
    summary["needle_model"] = needle_model_->name();
    summary["contact_law"] = run_->contact_model().law();
    summary["model_level"] = model_level_of(scene_);
    summary["subcycling"] = scene_.solver.coupling.subcycling;
    summary["energy_mJ"] = {{"drive_work", e.drive_work_mJ}, {"tissue_internal", e.tissue_internal_mJ}, {"tissue_kinetic", e.tissue_kinetic_mJ},
                            {"needle_kinetic", e.needle_kinetic_mJ}, {"needle_strain", e.needle_strain_mJ}, {"contact_work", e.contact_work_mJ},
                            {"penalty", e.penalty_energy_mJ}, {"friction_dissipation", e.friction_dissipation_mJ}, {"cannula_work", e.cannula_work_mJ}};
    if (firing_) {  // the fired cannula's terms (absent from a run without one)
      summary["energy_mJ"]["needle_held"] = e.needle_held_mJ;
      summary["energy_mJ"]["cannula_firing_wall"] = e.firing_work_mJ;
    }
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
      // The insertion's target (a fired cannula's stroke takes its own: the sample's entry).
      summary["tissue_mass_scaling"] = {{"target_dt_ms", insertion_mass_scaling_dt_ms_ > 0 ? insertion_mass_scaling_dt_ms_ : scaling->target_dt_ms()},
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
    summary["strain_probes"]["end"] = at_insertion_end_ ? at_insertion_end_->strain_probes
                                                        : strain_probes_json(run_strain_probes(*run_, built_, scene_),
                                                                             needle_model_->drive_displacement_mm().norm(), deflection_mm());
    if (firing_) add_sample_summary(summary);
    if (run_->cutting()) run_->cutting()->add_summary(summary);
    for (const auto& separation : run_->separations()) separation->add_summary(summary, run_->tissue());
  }
  // The sample the fired cannula encloses (solver/insertion/tissue_sample.h), the stroke, and the groove before the firing.
  void add_sample_summary(json& summary) const {
    if (!sample_) return;  // the run stopped before its outputs were closed
    const TissueSample& sample = *sample_;
    const TissueSample& touched_during_stroke = *sample_touched_during_stroke_;
    const CannulaStroke& s = firing_->stroke();
    summary["sample"] = {
        {"I_s_mm", sample.I_s_mm()},
        {"I_s_measure", kSampleLengthMeasure},
        {"floor_length_mm", sample.floor_length_mm},
        {"floor_covered_mm", sample.floor_covered_mm},
        {"floor_length_during_stroke_mm", touched_during_stroke.floor_length_mm},
        {"floor_layer_length_mm", sample.floor_layer_length_mm},
        {"floor_layer_covered_mm", sample.floor_layer_covered_mm},
        {"floor_layer_particles", sample.floor_layer_particles},
        {"length_mm", sample.length_mm},
        {"volume_mm3", sample.volume_mm3},
        {"mass_g", sample.mass_g},
        {"particles", sample.particles},
        {"floor_particles", sample.floor_particles},
        {"back_x_mm", sample.back_x_mm},
        {"front_x_mm", sample.front_x_mm},
        {"cannula", {{"speed_m_per_s", s.speed_mm_per_ms}, {"start_time_ms", s.start_time_ms}, {"end_time_ms", s.end_time_ms()},
                     {"start_x_mm", s.start_x_mm}, {"stop_x_mm", s.stop_x_mm}, {"front_x_mm_at_end", s.front_x_mm(run_->time_ms())},
                     {"bore_radius_mm", firing_->tube().inner_radius_mm}, {"outer_radius_mm", firing_->tube().outer_radius_mm},
                     {"tissue_mass_scaling_dt_ms", run_->tissue_dynamics().mass_scaling() ? run_->tissue_dynamics().mass_scaling()->target_dt_ms() : 0.0},
                     {"wall_pushes", firing_->pushes()}, {"max_push_mm", firing_->max_push_mm()}, {"wall_work_mJ", firing_->work_mJ()}}},
        {"definition", "solver/insertion/tissue_sample.h: the particles inside the cannula's mid-wall radius, between the groove's walls within "
                       "the stroke, above the groove floor less half a spacing, when the cannula stops, in the needle's reference frame; "
                       "floor_layer_*: of those whose centre lies within the contact's skin and a quarter spacing of the floor, by geometry, "
                       "their extent along the axis and the length of the axis under them; I_s_mm (the length compared with the paper's) is "
                       "floor_layer_covered_mm, the length of groove floor the sample rests on; floor_length_mm, floor_covered_mm: the same "
                       "two for the particles the contact lists as touching the floor when it stops (floor_length_during_stroke_mm: at any "
                       "record during the stroke), kept beside it; x in the needle's reference frame (tip point A at 0)"}};
  }
  std::string log_steps(double solve_s) const override {
    return fmt::format("{} coupling steps and {} needle steps in {:.2f} s, energy balance error {:.3g}, max penetration {:.3g} mm, {} particles "
                       "inside at the end; the coupling step set by {}",
                       run_->steps(), run_->needle_steps(), solve_s, run_->energy().balance_error(), run_->max_depth_mm(),
                       run_->contact().particles_inside, step_limits_words());
  }
  // "tissue 1446 times, interval_end once": what set the coupling steps (StepLimit), most first.
  std::string step_limits_words() const {
    std::vector<std::pair<long, std::string>> counts;
    for (int k = 0; k < kStepLimits; ++k)
      if (const long n = run_->step_limits()[static_cast<size_t>(k)]; n > 0) counts.emplace_back(n, step_limit_name(static_cast<StepLimit>(k)));
    std::sort(counts.begin(), counts.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    std::string words;
    for (const auto& [n, name] : counts) words += fmt::format("{}{} {}", words.empty() ? "" : ", ", name, n == 1 ? "once" : fmt::format("{} times", n));
    return words.empty() ? "nothing (no step)" : words;
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
  std::unique_ptr<CannulaFiring> firing_;  // the cannula fired after the travel (null: none); outlives run_, whose edge cut reads it
  std::unique_ptr<CoupledInsertion> run_;
  struct InsertionEnd {  // with a fired cannula: what the insertion's end left
    Eigen::Vector3d tip_mm, drive_mm;
    GrooveFill groove;
    json strain_probes;
  };
  std::optional<InsertionEnd> at_insertion_end_;
  double insertion_end_row_ms_ = std::nan("");  // the time of the row written at the insertion's end (a fired cannula's run)
  std::vector<std::uint8_t> touched_floor_;  // per particle: touched the groove floor at a record during the stroke
  double insertion_mass_scaling_dt_ms_ = 0;  // the tissue's mass scaling target before a firing retargeted it (0: none did)
  std::optional<TissueSample> sample_, sample_touched_during_stroke_;  // at the run's end (close_outputs)
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
  std::ifstream summary(folder / "summary.json");
  if (!summary.good() || !std::filesystem::is_regular_file(folder / "scene.json")) return false;
  // The worker threads are left out of the comparison: every kernel is a gather (core/parallel.h), so a run's
  // results do not depend on them (a test runs the same scene on one and two threads and compares the histories).
  auto without_threads = [](json scene_json) {
    if (scene_json.contains("solver") && scene_json["solver"].is_object()) scene_json["solver"].erase("threads");
    return scene_json;
  };
  try {
    // A run stopped by Ctrl-C holds what it had so far, not a result: it runs again.
    if (json::parse(summary).value("status", std::string()) == "interrupted") return false;
    // The stored scene read as a run's (runs/scene.h: an older layout or older keys read as what they meant), written
    // again as today's effective scene, against this scene's.
    return without_threads(scene_to_json(read_run_scene((folder / "scene.json").string()))) == without_threads(scene_to_json(scene));
  } catch (const json::exception&) {
    return false;  // an unreadable folder holds no run
  } catch (const InputError&) {
    return false;  // nor one whose scene this code cannot read
  }
}

bool run_insertion_unless_done(const Scene& scene, const RunOptions& options) {
  const bool done = folder_holds_run_of(scene, options.out_dir);
  if (!done) run_insertion(scene, options);
  return done;
}

}  // namespace needle
