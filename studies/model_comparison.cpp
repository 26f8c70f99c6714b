#include "studies/model_comparison.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "runs/json_file.h"
#include "core/input_error.h"
#include "plot/bar_chart.h"

namespace needle {
using json = nlohmann::json;

ComparedModel parse_compared_model(const std::string& text, const char* flag) {
  const auto eq = text.find('=');
  NEEDLE_REQUIRE(eq != std::string::npos && eq > 0 && eq + 1 < text.size(),
                 fmt::format("{} '{}': give LABEL=FILE, e.g. \"0.4 mm, cut=paper_04/results.json\"", flag, text));
  return {text.substr(0, eq), text.substr(eq + 1)};
}

ModelResults read_model_results(const ComparedModel& model) {
  const json j = read_json_file(model.results_path, "compared results");
  NEEDLE_REQUIRE(j.contains("needles") && j["needles"].is_object(),
                 fmt::format("{}: no 'needles' object (give the results.json of a `needle paper` report)", model.results_path));
  ModelResults m;
  m.label = model.label;
  m.path = model.results_path;
  m.tissue = j.value("tissue", std::string("n/a"));
  m.tissue_E_MPa = number_or_nan(j, "tissue_E_MPa");
  for (const auto& [name, v] : j["needles"].items()) {
    NEEDLE_REQUIRE(v.is_object(), fmt::format("{}: needles.{} must be an object", model.results_path, name));
    NeedleOutcome r;
    r.name = name;
    r.deflection_mm = number_or_nan(v, "deflection_mm");
    r.groove_fill = number_or_nan(v, "groove_fill");
    r.status = v.value("status", std::string("unknown"));
    r.insertion_mm = number_or_nan(v, "insertion_mm");
    if (v.contains("sample") && v["sample"].is_object()) {
      r.sample_I_s_mm = number_or_nan(v["sample"], "I_s_mm");
      r.sample_contact_extent_mm = number_or_nan(v["sample"], "contact_extent_mm");
    }
    m.needles.push_back(r);
  }
  return m;
}

RgbImage model_bars(const std::vector<ModelResults>& models, const std::vector<std::string>& needles,
                    const std::vector<PaperReferenceNeedle>& reference) {
  BarChart chart;
  chart.title = "Deflection at the end: each model, the experiment, LS-DYNA";
  chart.y_label = "deflection (mm)";
  chart.categories = needles;
  for (size_t k = 0; k < models.size(); ++k) {
    BarSeries s{models[k].label, {}, compared_model_colour(static_cast<int>(k))};
    for (const std::string& n : needles) {
      const NeedleOutcome* r = find_outcome(models[k].needles, n);
      s.values.push_back(r ? r->deflection_mm : kNaN);
    }
    chart.series.push_back(s);
  }
  BarSeries experiment{"experiment", {}, kExperiment}, lsdyna{"LS-DYNA (paper)", {}, kLsDyna};
  for (const std::string& n : needles) {
    const PaperReferenceNeedle* ref = find_reference(reference, n);
    experiment.values.push_back(ref ? ref->deflection_experiment_mm : kNaN);
    lsdyna.values.push_back(ref ? ref->deflection_lsdyna_mm : kNaN);
  }
  chart.series.push_back(experiment);
  chart.series.push_back(lsdyna);
  return draw_bar_chart(chart);
}

std::pair<double, double> ratio_to_sb_span(const std::vector<ModelResults>& models, const std::string& needle) {
  double lo = kNaN, hi = kNaN;
  for (const ModelResults& m : models) {
    const NeedleOutcome* r = find_outcome(m.needles, needle);
    const NeedleOutcome* sb = find_outcome(m.needles, "SB");
    if (!r || !sb || !std::isfinite(r->deflection_mm / sb->deflection_mm)) continue;  // also SB at 0
    const double q = r->deflection_mm / sb->deflection_mm;
    lo = std::isfinite(lo) ? std::min(lo, q) : q;
    hi = std::isfinite(hi) ? std::max(hi, q) : q;
  }
  return {lo, hi};
}

// The section that sets this report beside other models: delta (and its ratio to SB's, which does not
// depend on E to first order), the targets each model meets, and the groove fill.
std::string models_section(const std::vector<ModelResults>& models, const std::vector<std::string>& needles,
                           const std::vector<PaperReferenceNeedle>& reference) {
  std::string md = "## The same needles under other models\n\n";
  md += "Each row is a `needle paper` report (its results.json). In brackets: delta / delta_SB. That ratio does not depend "
        "on E to first order, so it compares models whether or not each was calibrated.\n\n";
  md += "| model | tissue | E (MPa) |";
  std::string rule = "|---|---|---|";
  for (const std::string& n : needles) md += fmt::format(" {} |", n), rule += "---|";
  md += " targets met at its E |\n" + rule + "---|\n";
  auto ratio = [](double d, double sb) { return std::isfinite(d) && std::isfinite(sb) && sb != 0 ? fmt::format(" ({:+.2f})", d / sb) : std::string(); };
  for (const ModelResults& m : models) {
    const NeedleOutcome* sb = find_outcome(m.needles, "SB");
    md += fmt::format("| {} | {} | {} |", m.label, m.tissue, std::isfinite(m.tissue_E_MPa) ? fmt::format("{:.4g}", m.tissue_E_MPa) : "n/a");
    for (const std::string& n : needles) {
      const NeedleOutcome* r = find_outcome(m.needles, n);
      md += r ? fmt::format(" {}{}{} |", fmt_mm(r->deflection_mm), n == "SB" ? "" : ratio(r->deflection_mm, sb ? sb->deflection_mm : kNaN),
                            r->status == "finished" ? "" : " stopped")
              : " |";
    }
    const std::vector<PaperTarget> targets = evaluate_paper_targets(m.needles, reference);
    const auto checked = std::count_if(targets.begin(), targets.end(), [](const PaperTarget& t) { return t.checked; });
    const auto met = std::count_if(targets.begin(), targets.end(), [](const PaperTarget& t) { return t.checked && t.met; });
    md += fmt::format(" {} of {} |\n", met, checked);
  }
  for (const bool experiment : {true, false}) {
    const PaperReferenceNeedle* sb = find_reference(reference, "SB");
    md += experiment ? "| experiment (paper) | | |" : "| LS-DYNA (paper) | 0.4 mm SPG particles, bond failure | |";
    for (const std::string& n : needles) {
      const PaperReferenceNeedle* ref = find_reference(reference, n);
      if (!ref) {
        md += " |";
        continue;
      }
      const double d = experiment ? ref->deflection_experiment_mm : ref->deflection_lsdyna_mm;
      const double d_sb = sb ? (experiment ? sb->deflection_experiment_mm : sb->deflection_lsdyna_mm) : kNaN;
      md += fmt::format(" {:+.2f}{} |", d, n == "SB" ? "" : ratio(d, d_sb));
    }
    md += " |\n";
  }
  // Does the spread between the models cover the experiment? (A model choice then moves delta across
  // it; where none does, no choice among these reaches the measurement.)
  md += "\n";
  for (const std::string& n : needles) {
    const PaperReferenceNeedle* ref = find_reference(reference, n);
    const PaperReferenceNeedle* ref_sb = find_reference(reference, "SB");
    if (n == "SB" || !ref || !ref_sb || ref_sb->deflection_experiment_mm == 0) continue;
    const auto [lo, hi] = ratio_to_sb_span(models, n);
    if (!std::isfinite(lo)) continue;
    const double e = ref->deflection_experiment_mm / ref_sb->deflection_experiment_mm;
    md += fmt::format("- {}: the models' delta / delta_SB span {:+.2f} to {:+.2f}; the experiment's {:+.2f} lies {}.\n", n, lo, hi, e,
                      e >= lo && e <= hi ? "inside: the model choices move it across the measurement"
                                         : "outside: none of these models reaches it");
  }
  md += "\nGroove fill (the measure of this report, above):\n\n| model |";
  rule = "|---|";
  for (const std::string& n : needles) md += fmt::format(" {} |", n), rule += "---|";
  md += "\n" + rule + "\n";
  for (const ModelResults& m : models) {
    md += fmt::format("| {} |", m.label);
    for (const std::string& n : needles) {
      const NeedleOutcome* r = find_outcome(m.needles, n);
      md += r ? fmt::format(" {} |", fmt_mm(r->groove_fill, "{:.3f}")) : " |";
    }
    md += "\n";
  }
  md += "\n![models](models.png)\n\n";
  return md;
}

}  // namespace needle
