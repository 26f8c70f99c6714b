#include "studies/paper_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "runs/csv_table.h"
#include "runs/json_file.h"
#include "runs/json_lines.h"
#include "runs/provenance_json.h"
#include "runs/run_summary.h"
#include "studies/paper_observations.h"
#include "solver/insertion/tissue_sample.h"
#include "studies/paper_sampling.h"
#include "studies/run_model_description.h"
#include "runs/scene.h"
#include "runs/scene_key_spellings.h"
#include "studies/target_gaps.h"
#include "geometry/cad_solid.h"
#include "geometry/grinding_recipe.h"
#include "core/input_error.h"
#include "geometry/mesh_io.h"
#include "geometry/render_png.h"
#include "geometry/tip_report.h"
#include "plot/bar_chart.h"
#include "plot/line_plot.h"

namespace needle {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// The parameter besides E fitted to a needle, named as fitted, with its leave-one-needle-out errors: when the fitted
// needle's run here uses the record's value (the record: studies/sensitivity/second_parameter.py --record).
struct FittedParameter {
  std::string needle, name;  // empty: nothing but E is fitted in these runs
  std::string key;
  double value = kNaN;
  std::string section;  // the report's section
};

FittedParameter fitted_parameter(const PaperReportInput& in, const fs::path& dir) {
  if (in.fitted_path.empty() || !fs::is_regular_file(in.fitted_path)) return {};
  const json record = read_json_file(in.fitted_path, "fitted parameter record");
  // The key as scenes spell it today (a record of an older study may spell it the older way: runs/scene_key_spellings.h).
  const std::string key = current_scene_key(record.value("key", std::string())), needle = record.value("fitted_on", std::string());
  const double value = record.value("value", kNaN);
  const fs::path scene_path = dir / "runs" / needle / "scene.json";
  if (key.empty() || needle.empty() || !std::isfinite(value) || !fs::is_regular_file(scene_path)) return {};
  std::string pointer;
  for (size_t start = 0; start <= key.size();) {
    const size_t end = std::min(key.find('.', start), key.size());
    pointer += "/" + json_pointer_token(key.substr(start, end - start));
    start = end + 1;
  }
  // The run's scene as today's effective scene, whatever layout it was stored in.
  const json scene = scene_to_json(read_run_scene(scene_path.string()));
  const json::json_pointer at(pointer);
  if (!scene.contains(at) || !scene.at(at).is_number() || scene.at(at).get<double>() != value) return {};
  std::string md = fmt::format("## One more parameter fitted to a needle: {}, on {} alone\n\n", record.value("name", key), needle);
  md += fmt::format("`{}` = {:g} {} in these runs is fitted on {} ({:.4g} fitted, rounded; the study: `{}`). {}'s deflection "
                    "here is therefore a fit, not a prediction, as SB's is through E. Leave one needle out: the value fitted to "
                    "the other two multi-bevel needles (E calibrated on SB), the held-out needle predicted:\n\n",
                    key, value, record.value("unit", std::string()), needle, record.value("value_fitted", kNaN),
                    record.value("study", std::string()), needle);
  md += "| held out | fitted on | value | predicted (mm) | measured (mm) | error (mm) |\n|---|---|---|---|---|---|\n";
  for (const json& h : record.value("leave_one_out", json::array()))
    md += fmt::format("| {} | {} | {:.3g}{} | {:+.3f} | {:+.2f} | {:+.3f} |\n", h.value("held_out", std::string()),
                      fmt::join(h.value("fitted_on", std::vector<std::string>{}), ", "), h.value("value", kNaN),
                      h.value("at_range_end", false) ? " (range end)" : "", h.value("prediction_mm", kNaN),
                      h.value("prediction_mm", kNaN) - h.value("error_mm", kNaN), h.value("error_mm", kNaN));
  md += "\n";
  return {needle, record.value("name", key), key, value, md};
}

// The table's rows up to time_ms (all of them if it has no time_ms column or the time is not a number).
void keep_rows_until(CsvTable& table, double time_ms) {
  if (!std::isfinite(time_ms) || !table.has("time_ms")) return;
  const size_t t = table.index("time_ms");
  table.rows.erase(std::remove_if(table.rows.begin(), table.rows.end(), [&](const std::vector<double>& row) { return !(row[t] <= time_ms + 1e-9); }),
                   table.rows.end());
}

// What one needle's run folder says.
struct NeedleRun : NeedleOutcome {
  std::string folder, reason;
  double runtime_s = kNaN, floor_contact_fraction = kNaN, mean_gap_mm = kNaN, max_energy_error = kNaN, max_penetration_mm = kNaN;
  double sample_length_mm = kNaN, sample_volume_mm3 = kNaN;  // a fired cannula's (I_s and the contact's extent: NeedleOutcome's)
  long sample_floor_particles = 0, sample_floor_layer_particles = 0;
  long bonds_broken = 0, bonds_cut_by_needle = 0, particles_inside = 0, steps = 0, particles = 0;
  std::string model_description;  // from the run's scene.json: the particles, the needle's cut, the law and the drive where not the paper's
  bool needle_cuts = false;       // the scene's tissue.contact.cuts_bonds
  CsvTable history, facets;
  json summary;  // the run's summary.json
};

NeedleRun read_run(const std::string& out_dir, const std::string& name) {
  NeedleRun r;
  r.name = name;
  r.folder = (fs::path(out_dir) / "runs" / name).string();
  const std::string summary_path = (fs::path(r.folder) / "summary.json").string();
  NEEDLE_REQUIRE(fs::exists(summary_path), fmt::format("no run of {}: '{}' is missing (run `needle paper` without --report-only first)", name, summary_path));
  const json s = read_json_file(summary_path, "run summary");
  r.summary = s;
  const RunOutcome o = run_outcome(s);
  r.status = o.status;
  r.reason = o.reason;
  r.deflection_mm = o.deflection_mm;
  r.insertion_mm = o.insertion_mm;
  r.runtime_s = o.runtime_s;
  r.max_energy_error = o.max_energy_balance_error;
  r.max_penetration_mm = o.max_penetration_mm;
  r.bonds_broken = s.value("bonds_broken", 0L);
  r.bonds_cut_by_needle = s.value("bonds_cut_by_needle", 0L);
  r.particles_inside = o.particles_inside;
  r.steps = o.steps;
  r.groove_fill = o.groove_fill;
  if (s.contains("groove") && s["groove"].is_object()) {
    r.floor_contact_fraction = number_or_nan(s["groove"], "floor_contact_fraction");
    r.mean_gap_mm = number_or_nan(s["groove"], "mean_gap_mm");
  }
  if (s.contains("sample") && s["sample"].is_object()) {
    r.sample_I_s_mm = o.sample_I_s_mm;
    r.sample_contact_extent_mm = o.sample_contact_extent_mm;
    r.sample_length_mm = number_or_nan(s["sample"], "length_mm");
    r.sample_volume_mm3 = number_or_nan(s["sample"], "volume_mm3");
    r.sample_floor_particles = s["sample"].value("floor_particles", 0L);
    r.sample_floor_layer_particles = s["sample"].value("floor_layer_particles", 0L);
  }
  r.particles = s.value("particles", 0L);
  const fs::path scene_path = fs::path(r.folder) / "scene.json";
  if (fs::exists(scene_path)) {
    const Scene scene = read_run_scene(scene_path.string());
    r.model_description = describe_run_model(scene, r.particles);
    r.needle_cuts = scene.tissue.separation.needle_cut;
  }
  r.history = read_csv_table((fs::path(r.folder) / "history.csv").string());
  r.facets = read_csv_table((fs::path(r.folder) / "facet_forces.csv").string());
  // A run that fired the cannula goes on past its insertion with the needle held: its curves and end loads are the
  // insertion's, up to the instant its deflection is read (summary "needle_held": from_ms).
  if (s.contains("needle_held") && s["needle_held"].is_object()) {
    const double insertion_end_ms = number_or_nan(s["needle_held"], "from_ms");
    for (CsvTable* table : {&r.history, &r.facets}) keep_rows_until(*table, insertion_end_ms);
  }
  return r;
}

// Each needle's sample for the sampling section, with the paper's measured length.
std::vector<SampledNeedle> sampled_needles(const std::vector<NeedleRun>& runs, const std::vector<PaperReferenceNeedle>& reference) {
  std::vector<SampledNeedle> sampled;
  for (const NeedleRun& r : runs) {
    const PaperReferenceNeedle* ref = find_reference(reference, r.name);
    sampled.push_back({r.name, r.sample_I_s_mm, r.sample_floor_layer_particles, r.sample_contact_extent_mm, r.sample_floor_particles,
                       r.sample_length_mm, r.sample_volume_mm3, r.floor_contact_fraction, ref ? ref->sample_length_mm : kNaN});
  }
  return sampled;
}

// The replicas' samples (their results.json "sample"; none where they did not fire the cannula).
std::vector<SampledReplica> sampled_replicas(const std::vector<ModelResults>& replicas) {
  std::vector<SampledReplica> out;
  for (const ModelResults& m : replicas) {
    SampledReplica r{m.label, {}};
    for (const NeedleOutcome& n : m.needles) r.needles.push_back({n.name, n.sample_I_s_mm, 0, n.sample_contact_extent_mm, 0, kNaN, kNaN, kNaN, kNaN});
    out.push_back(r);
  }
  return out;
}

// The tissue's y force on the tip facets, the groove (floor and walls) and the shaft in the run's last
// facet_forces.csv row; NaN where the run recorded none.
NeedleEndLoads end_loads(const NeedleRun& r) {
  NeedleEndLoads l;
  l.name = r.name;
  if (r.facets.rows.empty()) return l;
  l.tip_facets_N = l.groove_N = l.shaft_N = 0;
  const std::vector<double>& last = r.facets.rows.back();
  const std::string suffix = "_fy_N";
  for (size_t k = 0; k < r.facets.columns.size(); ++k) {
    const std::string& c = r.facets.columns[k];
    if (c.size() <= suffix.size() || c.compare(c.size() - suffix.size(), suffix.size(), suffix) != 0 || !std::isfinite(last[k])) continue;
    const std::string tag = c.substr(0, c.size() - suffix.size());
    if (tag == "groove_floor" || tag == "groove_wall") l.groove_N += last[k];
    else if (tag == "shaft") l.shaft_N += last[k];
    else if (tag != "base") l.tip_facets_N += last[k];
  }
  return l;
}

void save_png(const RgbImage& image, const std::string& path) {
  write_file_atomically(path, [&](const std::string& scratch) { write_png(image, scratch); });
}

void save_text(const std::string& text, const std::string& path) {
  write_file_atomically(path, [&](const std::string& scratch) {
    std::ofstream out(scratch);
    out << text;
    NEEDLE_REQUIRE(out.good(), fmt::format("cannot write '{}'", path));
  });
}

RgbImage deflection_plot(const std::vector<NeedleRun>& runs, const std::vector<PaperReferenceNeedle>& reference) {
  LinePlot plot;
  plot.title = "Tip deflection against insertion (circles: experiment at 30 mm)";
  plot.x_label = "insertion length (mm)";
  plot.y_label = "deflection of tip point A, +y up (mm)";
  for (size_t k = 0; k < runs.size(); ++k) {
    const NeedleRun& r = runs[k];
    PlotSeries s;
    s.label = r.name + (r.status == "finished" ? "" : " (stopped)");
    s.x = r.history.column("insertion_mm");
    s.y = r.history.column("deflection_mm");
    s.color = plot_color(static_cast<int>(k));
    plot.series.push_back(s);
    if (const PaperReferenceNeedle* ref = find_reference(reference, r.name)) {
      PlotSeries e;
      e.x = {30.0};
      e.y = {ref->deflection_experiment_mm};
      e.color = s.color;
      e.markers = true;
      plot.series.push_back(e);
    }
  }
  return draw_line_plot(plot);
}

// With replicas, each of our bars carries a whisker from the lowest to the highest deflection of that needle
// over this report and the replicas that ran it: a bar's distance from the experiment reads against it.
RgbImage deflection_bars(const std::vector<NeedleRun>& runs, const std::vector<PaperReferenceNeedle>& reference,
                         const ReplicaScatter& scatter) {
  BarChart chart;
  chart.title = "Deflection at the end of insertion: this toolkit, experiment, LS-DYNA";
  chart.y_label = "deflection (mm)";
  chart.range_label = "run-to-run spread: lowest to highest over this report and the replicas that ran the needle";
  BarSeries ours{"this toolkit", {}, kOurs}, experiment{"experiment", {}, kExperiment}, lsdyna{"LS-DYNA (paper)", {}, kLsDyna};
  for (const NeedleRun& r : runs) {
    chart.categories.push_back(r.name);
    ours.values.push_back(r.deflection_mm);
    const NeedleScatter* s = find_needle_scatter(scatter, r.name);
    ours.ranges.push_back(s ? deflection_range_mm(*s) : std::pair<double, double>{kNaN, kNaN});
    const PaperReferenceNeedle* ref = find_reference(reference, r.name);
    experiment.values.push_back(ref ? ref->deflection_experiment_mm : kNaN);
    lsdyna.values.push_back(ref ? ref->deflection_lsdyna_mm : kNaN);
  }
  chart.series = {ours, experiment, lsdyna};
  return draw_bar_chart(chart);
}

RgbImage groove_bars(const std::vector<NeedleRun>& runs, const std::vector<PaperReferenceNeedle>& reference) {
  BarChart chart;
  chart.title = "Groove fill beside the measured sample length";
  chart.y_label = "fraction";
  chart.value_format = "{:.2f}";
  double longest = 0;
  for (const PaperReferenceNeedle& r : reference) longest = std::max(longest, r.sample_length_mm);
  BarSeries fill{"groove fill", {}, kOurs}, contact{"floor contact fraction", {}, {44, 160, 44}},
      sample{"sample length / longest (experiment)", {}, kExperiment};
  for (const NeedleRun& r : runs) {
    chart.categories.push_back(r.name);
    fill.values.push_back(r.groove_fill);
    contact.values.push_back(r.floor_contact_fraction);
    const PaperReferenceNeedle* ref = find_reference(reference, r.name);
    sample.values.push_back(ref && longest > 0 ? ref->sample_length_mm / longest : kNaN);
  }
  chart.series = {fill, contact, sample};
  return draw_bar_chart(chart);
}

// A facet's colour, the same in every needle's panel (the palette's order otherwise shifts with the
// facets a needle has: the groove floor was green for SB and orange for the others).
Rgb facet_colour(const std::string& facet, int fallback) {
  static const std::map<std::string, int> palette_index = {{"top", 0},          {"bottom", 1},     {"side_pos", 2}, {"side_neg", 2},
                                                           {"groove_floor", 3}, {"groove_wall", 4}, {"shaft", 5},   {"lancet_pos", 6},
                                                           {"lancet_neg", 6},   {"base", 7}};
  const auto it = palette_index.find(facet);
  return plot_color(it != palette_index.end() ? it->second : fallback);
}

// One panel per needle: the y force the tissue puts on each facet that carries any.
RgbImage facet_force_panels(const std::vector<NeedleRun>& runs) {
  const int panel_w = 760, panel_h = 480;
  const int columns = runs.size() > 1 ? 2 : 1, rows_n = static_cast<int>((runs.size() + 1) / 2);
  RgbImage image(columns * panel_w, std::max(1, rows_n) * panel_h);
  for (size_t k = 0; k < runs.size(); ++k) {
    const NeedleRun& r = runs[k];
    LinePlot plot;
    plot.title = fmt::format("{}: y force of the tissue on each facet", r.name);
    plot.x_label = "insertion length (mm)";
    plot.y_label = "force y (N), + up";
    plot.width_px = panel_w, plot.height_px = panel_h;
    const std::vector<double> x = r.facets.column("insertion_mm");
    int color = 0;
    for (const std::string& c : r.facets.columns) {
      const std::string suffix = "_fy_N";
      if (c.size() <= suffix.size() || c.compare(c.size() - suffix.size(), suffix.size(), suffix) != 0) continue;
      const std::vector<double> y = r.facets.column(c);
      double peak = 0;
      for (double v : y)
        if (std::isfinite(v)) peak = std::max(peak, std::abs(v));
      if (peak < 1e-6) continue;
      PlotSeries s;
      s.label = c.substr(0, c.size() - suffix.size());
      s.x = x;
      s.y = y;
      s.color = facet_colour(s.label, color++);
      plot.series.push_back(s);
    }
    if (plot.series.empty()) continue;
    image.paste(draw_line_plot(plot), static_cast<int>(k % 2) * panel_w, static_cast<int>(k / 2) * panel_h);
  }
  return image;
}

RgbImage tip_pictures(const std::vector<std::string>& names) {
  const int panel_w = 620, panel_h = 300, tile_h = 2 * panel_h + 100;
  const int columns = names.size() > 1 ? 2 : 1, rows_n = static_cast<int>((names.size() + 1) / 2);
  RgbImage image(columns * panel_w, std::max(1, rows_n) * tile_h);
  for (size_t k = 0; k < names.size(); ++k) {
    const GrindingRecipe recipe = preset_recipe(names[k]);
    const CadSolid solid = build_cad_solid(recipe, false);
    const TipReport report = make_tip_report(solid, {});
    RenderOptions o;
    o.panel_width_px = panel_w;
    o.panel_height_px = panel_h;
    o.title = fmt::format("{}   d_a = {}", names[k], report.d_a_mm ? fmt::format("{:+.2f} mm", *report.d_a_mm) : "n/a");
    o.view_from_x_mm = -std::max(report.tip_length_mm + 1.0, 3.5);
    image.paste(render_tip_image(solid.surface, o), static_cast<int>(k % 2) * panel_w, static_cast<int>(k / 2) * tile_h);
  }
  return image;
}

}  // namespace

void write_paper_report(const PaperReportInput& in) {
  std::vector<NeedleRun> runs;
  for (const std::string& name : in.needles) runs.push_back(read_run(in.out_dir, name));
  const std::vector<NeedleOutcome> outcomes(runs.begin(), runs.end());
  const std::vector<PaperTarget> targets = evaluate_paper_targets(outcomes, in.reference);
  const fs::path dir(in.out_dir);
  const std::string tissue = runs.empty() ? std::string() : runs.front().model_description;
  std::vector<ModelResults> models;
  if (!in.compare.empty()) {
    ModelResults self;
    self.label = in.label;
    self.tissue = tissue.empty() ? "n/a" : tissue;
    self.tissue_E_MPa = in.tissue_E_MPa;
    self.needles = outcomes;
    models.push_back(self);
    for (const ComparedModel& c : in.compare) models.push_back(read_model_results(c));
  }
  std::vector<ModelResults> replicas;
  for (const ComparedModel& c : in.replicas) replicas.push_back(read_model_results(c));
  const ReplicaScatter scatter = replica_scatter(outcomes, targets, replicas, in.reference);
  const std::vector<SampledNeedle> sampled = sampled_needles(runs, in.reference);
  const std::vector<SampledReplica> sampled_reps = sampled_replicas(replicas);

  // results.json
  json needles = json::object();
  for (const NeedleRun& r : runs) {
    json n = {{"deflection_mm", r.deflection_mm},
              {"groove_fill", r.groove_fill},
              {"groove_floor_contact_fraction", r.floor_contact_fraction},
              {"groove_mean_gap_mm", r.mean_gap_mm},
              {"runtime_s", r.runtime_s},
              {"status", r.status},
              {"insertion_mm", r.insertion_mm},
              {"max_energy_balance_error", r.max_energy_error},
              {"bonds_broken", r.bonds_broken},
              {"bonds_cut_by_needle", r.bonds_cut_by_needle},
              {"run_folder", fs::path(r.folder).lexically_relative(dir).string()}};
    if (!r.reason.empty()) n["reason"] = r.reason;
    if (const NeedleScatter* s = find_needle_scatter(scatter, r.name); s && s->replicas_with_needle > 0) {
      n["deflection_spread_mm"] = s->spread_mm;
      n["replicas_with_needle"] = s->replicas_with_needle;
    }
    if (const PaperReferenceNeedle* ref = find_reference(in.reference, r.name)) {
      n["deflection_experiment_mm"] = ref->deflection_experiment_mm;
      n["deflection_lsdyna_mm"] = ref->deflection_lsdyna_mm;
      n["error_vs_experiment_mm"] = r.deflection_mm - ref->deflection_experiment_mm;
      n["sample_length_mm"] = ref->sample_length_mm;
    }
    if (std::isfinite(r.sample_I_s_mm))
      n["sample"] = {{"I_s_mm", r.sample_I_s_mm},
                     {"I_s_measure", kSampleLengthMeasure},
                     {"contact_extent_mm", r.sample_contact_extent_mm},
                     {"floor_layer_particles", r.sample_floor_layer_particles},
                     {"contact_particles", r.sample_floor_particles},
                     {"length_mm", r.sample_length_mm},
                     {"volume_mm3", r.sample_volume_mm3}};
    needles[r.name] = n;
  }
  json target_list = json::array();
  for (size_t i = 0; i < targets.size(); ++i) {
    const PaperTarget& t = targets[i];
    json target = {{"target", t.what}, {"numbers", t.numbers}, {"met", t.met}, {"checked", t.checked}};
    if (!replicas.empty()) target["replicas"] = {{"checked", scatter.targets[i].checked}, {"met", scatter.targets[i].met}};
    target_list.push_back(target);
  }
  std::vector<ObservedRun> observed;
  for (const NeedleRun& r : runs) observed.push_back({r.name, r.summary});
  json results = {{"needles", needles},
                  {"tissue_E_MPa", in.tissue_E_MPa},
                  {"tissue_E_source", in.tissue_E_source},
                  {"groove_fill_definition",
                   "mean over the groove's length inside the tissue of the share of the groove's depth (floor to the rod's top) "
                   "that tissue fills, measured in the needle's own frame at the end of insertion (report.md, docs/paper.md)"},
                  {"targets", target_list},
                  {"tissue", tissue},
                  {"reference", fs::proximate(in.reference_path).string()},
                  {"provenance", provenance_json()}};
  for (const ModelResults& m : replicas) results["replicas"].push_back({{"label", m.label}, {"results", m.path}});
  const FittedParameter fitted = fitted_parameter(in, dir);
  if (!fitted.needle.empty())
    results["fitted_parameter"] = {{"key", fitted.key}, {"name", fitted.name}, {"value", fitted.value}, {"fitted_on", fitted.needle},
                                   {"record", fs::proximate(in.fitted_path).string()}};
  if (const json observations = paper_observations_json(observed); !observations.empty()) results["observations"] = observations;
  if (std::any_of(sampled.begin(), sampled.end(), [](const SampledNeedle& n) { return std::isfinite(n.I_s_mm); })) {
    const auto verdict_json = [](const SamplingVerdict& v) {
      return json{{"ranked", v.ranked}, {"ratios_within", v.ratios_within}, {"worst_ratio_miss", v.worst_ratio_miss}};
    };
    json lattices = json::array();
    for (const SamplingLattice& l : judge_sampling_lattices(sampled, sampled_reps))
      lattices.push_back({{"label", l.label}, {"I_s", verdict_json(l.I_s)}, {"contact_extent", verdict_json(l.contact_extent)}});
    results["sampling"] = {{"I_s_measure", "floor_layer_covered_mm: the length of groove floor the enclosed tissue rests on"},
                           {"ratio_tolerance", SamplingVerdict::kRatioTolerance},
                           {"lattices", lattices}};
  }

  // The pictures.
  save_png(deflection_plot(runs, in.reference), (dir / "deflection_vs_insertion.png").string());
  save_png(deflection_bars(runs, in.reference, scatter), (dir / "deflection_bars.png").string());
  save_png(groove_bars(runs, in.reference), (dir / "groove_fill.png").string());
  save_png(facet_force_panels(runs), (dir / "facet_forces.png").string());
  std::vector<std::string> paper_tips;
  for (const std::string& n : in.needles)
    if (is_paper_needle(n)) paper_tips.push_back(n);
  const bool tips = in.draw_tips && !paper_tips.empty();
  if (tips) save_png(tip_pictures(paper_tips), (dir / "tips.png").string());
  if (!models.empty()) save_png(model_bars(models, in.needles, in.reference), (dir / "models.png").string());

  // report.md
  std::string md;
  md += "# Multi-bevel needles in PVC: this toolkit against the paper\n\n";
  md += fmt::format("Regenerate: `{}`\n\n", in.command_line);
  md += fmt::format("Tissue E = {:.4g} MPa ({}). Every other number is the paper's (shared/SPEC.md); "
                    "the reference values come from `{}`.\n\n",
                    in.tissue_E_MPa, in.tissue_E_source, fs::proximate(in.reference_path).string());
  if (!tissue.empty()) md += fmt::format("Tissue: {}.\n\n", tissue);
  if (!in.calibration_path.empty()) {
    const json cal = read_json_file(in.calibration_path, "calibration");
    md += fmt::format("## Calibration of E on {} alone\n\n", cal.value("needle", std::string("SB")));
    md += fmt::format("Target {:+.2f} mm; each row a full run of the paper's scene (`needle calibrate`). The others are predictions.\n\n",
                      cal.value("target_deflection_mm", kNaN));
    md += "| E (MPa) | deflection (mm) | status |\n|---|---|---|\n";
    for (const json& r : cal.value("runs", json::array()))
      md += fmt::format("| {:.4g} | {:+.3f} | {} |\n", r.value("E_MPa", kNaN), r.value("deflection_mm", kNaN), r.value("status", std::string()));
    const json sensitivity = cal.value("sensitivity_mm_per_MPa", json());
    const json relative = cal.value("relative_sensitivity", json());
    const json pair = cal.value("sensitivity_from_E_MPa", json());
    md += fmt::format("\nChosen: E = {:.4g} MPa ({}). ", cal.value("tissue_E_MPa", kNaN),
                      cal.value("converged", false) ? "within the tolerance" : "the nearest run; not within the command's tolerance");
    if (sensitivity.is_number() && relative.is_number())
      md += fmt::format("Sensitivity near it: d delta / d E = {:.3g} mm per MPa, i.e. {:.2f} % of delta per % of E{}.\n\n",
                        sensitivity.get<double>(), relative.get<double>(),
                        pair.is_array() && pair.size() == 2
                            ? fmt::format(" (from the runs at E = {:.4g} and {:.4g} MPa)", pair[0].get<double>(), pair[1].get<double>())
                            : std::string(" (from the two runs nearest the target)"));
    else
      md += "Sensitivity: not measured (no second finished run near the chosen E; `needle calibrate` makes one unless "
            "`--sensitivity-step 0`).\n\n";
    // The calibration holds for this report only if its needle, run here at the chosen E, ends where
    // the calibration's run did: a different model (flags, spacing, cut) breaks that.
    const std::string cal_needle = cal.value("needle", std::string("SB"));
    const double cal_deflection = cal.value("deflection_mm", kNaN), cal_tolerance = cal.value("tolerance_mm", 0.05);
    for (const NeedleRun& r : runs)
      if (r.name == cal_needle && std::isfinite(cal_deflection) && std::isfinite(r.deflection_mm) &&
          std::abs(r.deflection_mm - cal_deflection) > cal_tolerance)
        md += fmt::format("**The calibration does not hold for these runs:** {} here ends at {:+.3f} mm, against {:+.3f} mm in the "
                          "calibration's run at the same E. These runs use another model than the calibration's; recalibrate "
                          "with the same flags before reading the others as predictions.\n\n",
                          r.name, r.deflection_mm, cal_deflection);
  }
  md += fitted.section;
  md += "## Deflection at the end of insertion (mm, +y up: the groove side)\n\n";
  md += "| needle | d_a (mm) | this toolkit | experiment | LS-DYNA (paper) | ours - experiment | status | run time |\n";
  md += "|---|---|---|---|---|---|---|---|\n";
  for (const NeedleRun& r : runs) {
    const PaperReferenceNeedle* ref = find_reference(in.reference, r.name);
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", r.name, ref ? fmt::format("{:+.2f}", ref->d_a_mm) : "",
                      fmt_mm(r.deflection_mm), ref ? fmt::format("{:+.2f}", ref->deflection_experiment_mm) : "",
                      ref ? fmt::format("{:+.2f}", ref->deflection_lsdyna_mm) : "",
                      ref ? fmt_mm(r.deflection_mm - ref->deflection_experiment_mm) : "",
                      r.status == "finished" ? "finished" : fmt::format("stopped at {:.1f} mm", r.insertion_mm),
                      std::isfinite(r.runtime_s) ? fmt::format("{:.1f} min", r.runtime_s / 60) : "n/a");
  }
  md += "\n![deflection against insertion](deflection_vs_insertion.png)\n\n![deflection bars](deflection_bars.png)\n\n";
  md += "## The paper's targets\n\n| target | numbers | verdict |\n|---|---|---|\n";
  for (size_t i = 0; i < targets.size(); ++i) {
    const PaperTarget& t = targets[i];
    std::string verdict = !t.checked ? "not checked (missing run)" : t.met ? "met" : "**not met**";
    // A target met here but not in a replica of the same model is met by chance: the verdict says so.
    if (t.met && !replicas.empty() && scatter.targets[i].met < scatter.targets[i].checked)
      verdict = fmt::format("met here, **not in {} of {} replicas** (run-to-run scatter below)",
                            scatter.targets[i].checked - scatter.targets[i].met, scatter.targets[i].checked);
    // A target on the needle a parameter was fitted to is met by the fit, not predicted.
    if (t.checked && !fitted.needle.empty() && t.needle == fitted.needle)
      verdict += fmt::format(" (by a fit: {} is fitted on {})", fitted.name, fitted.needle);
    md += fmt::format("| {} | {} | {} |\n", t.what, t.numbers, verdict);
  }
  {
    TargetGapInput gaps{targets, outcomes, {}, models, replicas.empty() ? nullptr : &scatter, in.reference};
    for (const NeedleRun& r : runs) gaps.loads.push_back(end_loads(r));
    const std::string section = target_gaps_section(gaps);
    if (!section.empty()) md += "\n" + section;
  }
  if (!replicas.empty()) md += "\n" + replica_section(scatter, replicas, targets);
  if (!models.empty()) md += "\n" + models_section(models, in.needles, in.reference);
  md += models.empty() ? "\n" : "";
  md += paper_observations_section(observed);
  md += "## Groove filling\n\n";
  md += "`groove_fill`: at the end of insertion, in the needle's own frame (each particle pulled back through the needle "
        "surface nearest it), the groove inside the tissue is cut into 0.05 mm slices along x; in each, the tissue's lowest "
        "edge (particle centre less half a spacing) inside the groove's section gives the filled share of the groove's depth, "
        "(rod top - edge) / (rod top - floor), clamped to [0, 1] and 0 where no tissue enters. `groove_fill` is the mean "
        "over the slices: 1 = tissue down to the floor everywhere, 0 = the groove stays empty. `floor contact` is the share "
        "of slices where a particle touches the groove floor; `mean gap` the mean height of the tissue's edge above the floor.\n\n";
  md += "| needle | groove_fill | floor contact | mean gap (mm) | measured sample length (mm) |\n|---|---|---|---|---|\n";
  for (const NeedleRun& r : runs) {
    const PaperReferenceNeedle* ref = find_reference(in.reference, r.name);
    md += fmt::format("| {} | {} | {} | {} | {} |\n", r.name, fmt_mm(r.groove_fill, "{:.3f}"), fmt_mm(r.floor_contact_fraction, "{:.3f}"),
                      fmt_mm(r.mean_gap_mm, "{:.3f}"), ref ? fmt::format("{:.1f}", ref->sample_length_mm) : "");
  }
  {
    // The secondary measure beside it: the paper's text speaks of tissue contact with the groove face.
    std::vector<const NeedleRun*> by_contact;
    for (const NeedleRun& r : runs) by_contact.push_back(&r);
    std::stable_sort(by_contact.begin(), by_contact.end(),
                     [](const NeedleRun* a, const NeedleRun* b) { return a->floor_contact_fraction > b->floor_contact_fraction; });
    std::string order;
    for (const NeedleRun* r : by_contact) order += (order.empty() ? "" : " > ") + r->name;
    md += fmt::format("\nRanked by floor contact (most first): {}. The measured sample lengths rank LMB (12.9) > SB (12.5) > AMB (9.9) > "
                      "HMB (8.6) mm, with SB and LMB statistically equal (paper: p = 1.000).\n",
                      order);
  }
  md += "\n![groove fill](groove_fill.png)\n\n";
  md += sampling_section(sampled, tissue, sampled_reps);
  md += "## Forces on the facets, and why a needle bends the way it does\n\n";
  md += "The y force the tissue exerts on each part of the needle at the end of insertion (N, +: pushes it up). The tip's "
        "facets and the groove floor are the paper's levers of the bending moment (M_t and M_b). The shaft is the rod's round "
        "surface over the whole inserted length, the groove's underside included: where the tissue cut below the tip point stays "
        "pressed down, it pushes the shaft up along all of it.\n\n";
  md += "| needle | tip facets | groove floor and walls | shaft | bonds broken (cut by the needle) |\n|---|---|---|---|---|\n";
  for (const NeedleRun& r : runs) {
    const NeedleEndLoads l = end_loads(r);
    if (!std::isfinite(l.shaft_N)) continue;
    md += fmt::format("| {} | {:+.3f} | {:+.3f} | {:+.3f} | {} ({}) |\n", r.name, l.tip_facets_N, l.groove_N, l.shaft_N, r.bonds_broken,
                      r.bonds_cut_by_needle);
  }
  const auto runs_cutting = std::count_if(runs.begin(), runs.end(), [](const NeedleRun& r) { return r.needle_cuts; });
  md += "\nThe needle bends the way the sum of the three columns points. The paper's tissue is cut at the tip point A and only "
        "slightly compressed in the groove. ";
  md += runs_cutting == static_cast<long>(runs.size()) ? "Here the needle cuts the bonds its body passes through (docs/insertion.md); the tissue above the cut rebounds "
                  "into the groove and presses on its floor, the tissue below stays pressed against the shaft, and the needle "
                  "follows the channel its tip cut (docs/paper.md discusses it).\n\n"
        : runs_cutting == 0
            ? "Here the needle cuts no bonds: the tissue separates by bond failure alone, as in the paper's model "
              "(`--no-needle-cut`; docs/paper.md compares it with the cut).\n\n"
            : "Here the needle cuts bonds in some runs only; where it does not, the tissue separates by bond failure alone "
              "(docs/insertion.md, docs/paper.md).\n\n";
  md += "![facet forces](facet_forces.png)\n\n";
  if (tips) md += "## The tips\n\n![the four tips](tips.png)\n\n";
  md += "## Runs\n\n| needle | folder | coupling steps | max energy-balance error | max penetration (mm) | particles inside at end | "
        "bonds broken | note |\n|---|---|---|---|---|---|---|---|\n";
  for (const NeedleRun& r : runs)
    md += fmt::format("| {} | `{}` | {} | {:.2g} | {:.3f} | {} | {} | {} |\n", r.name, fs::path(r.folder).lexically_relative(dir).string(), r.steps,
                      r.max_energy_error, r.max_penetration_mm, r.particles_inside, r.bonds_broken, r.reason.empty() ? "" : r.reason);
  md += "\nEach run folder holds history.csv, facet_forces.csv, summary.json, and needle.pvd / tissue.pvd for ParaView.\n";

  save_text(results.dump(2) + "\n", (dir / "results.json").string());
  save_text(md, (dir / "report.md").string());
}

}  // namespace needle
