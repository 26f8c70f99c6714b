#include "sweeps/sweep_table.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <map>
#include <set>

#include "core/input_error.h"
#include "geometry/mesh_io.h"
#include "plot/heat_map.h"
#include "plot/line_plot.h"
#include "runs/provenance_json.h"
#include "runs/json_file.h"
#include "studies/paper_results.h"

namespace needle {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return quoted + "\"";
}

std::string number_field(double x) { return std::isfinite(x) ? fmt::format("{}", x) : ""; }

std::string value_field(const json& v) {
  if (v.is_number()) return fmt::format("{}", v.get<double>());
  return csv_field(v.is_string() ? v.get<std::string>() : v.dump());
}

// The case's variables other than `variable`, as the key of its curve.
json others_of(const CaseResult& r, const std::string& variable) {
  json others = r.values;
  others.erase(variable);
  return others;
}

bool numeric_variable(const std::vector<CaseResult>& rows, const std::string& variable) {
  return !rows.empty() && std::all_of(rows.begin(), rows.end(), [&](const CaseResult& r) { return r.values.contains(variable) && r.values.at(variable).is_number(); });
}

// One curve per value of the other variables, each sorted by the variable.
std::vector<std::pair<json, std::vector<const CaseResult*>>> curves_along(const std::vector<CaseResult>& rows, const std::string& variable) {
  std::vector<std::pair<json, std::vector<const CaseResult*>>> curves;
  for (const CaseResult& r : rows) {
    const json others = others_of(r, variable);
    auto it = std::find_if(curves.begin(), curves.end(), [&](const auto& c) { return c.first == others; });
    if (it == curves.end()) {
      curves.push_back({others, {}});
      it = curves.end() - 1;
    }
    it->second.push_back(&r);
  }
  for (auto& c : curves)
    std::stable_sort(c.second.begin(), c.second.end(), [&](const CaseResult* a, const CaseResult* b) {
      return a->values.at(variable).get<double>() < b->values.at(variable).get<double>();
    });
  return curves;
}

void write_plot(const fs::path& path, const LinePlot& plot) {
  bool anything = false;
  for (const PlotSeries& s : plot.series)
    for (size_t k = 0; k < s.x.size(); ++k) anything = anything || std::isfinite(s.x[k] + s.y[k]);
  if (!anything) return;
  const RgbImage image = draw_line_plot(plot);
  write_file_atomically(path.string(), [&](const std::string& scratch) { write_png(image, scratch); });
}

void plot_against(const fs::path& dir, const std::string& variable, const std::vector<CaseResult>& rows, const std::string& reference_file) {
  const auto curves = curves_along(rows, variable);
  constexpr size_t kMaxCurves = 8;
  LinePlot deflection{fmt::format("Tip deflection at the end of the insertion against {}", variable), variable, "deflection (mm)", {}};
  LinePlot fill{fmt::format("Groove fill at the end of the insertion against {}", variable), variable, "groove fill (share of the depth)", {}};
  LinePlot sample{fmt::format("The fired cannula's sample length I_s against {}", variable), variable, "I_s (mm)", {}};
  for (size_t k = 0; k < curves.size() && k < kMaxCurves; ++k) {
    const std::string label = curves.size() == 1 ? "this toolkit" : describe_values(curves[k].first);
    PlotSeries d{label, {}, {}, plot_color(static_cast<int>(k))};
    d.markers = true;
    PlotSeries f = d, s = d;
    for (const CaseResult* r : curves[k].second) {
      const double x = r->values.at(variable).get<double>();
      const bool ok = r->status == "finished";
      d.x.push_back(x);
      d.y.push_back(ok ? r->deflection_mm : std::nan(""));
      f.x.push_back(x);
      f.y.push_back(ok ? r->groove_fill : std::nan(""));
      s.x.push_back(x);
      s.y.push_back(ok ? r->sample_I_s_mm : std::nan(""));
    }
    deflection.series.push_back(d);
    fill.series.push_back(f);
    sample.series.push_back(s);
  }
  if (variable == "d_a_mm" && !reference_file.empty() && fs::exists(reference_file)) {
    PlotSeries experiment{"the paper's experiment (SB, LMB, AMB, HMB)", {}, {}, kExperiment};
    PlotSeries measured_sample{"the paper's experiment (chicken breast)", {}, {}, kExperiment};
    measured_sample.line = false;
    measured_sample.markers = true;
    PlotSeries lsdyna{"the paper's LS-DYNA model", {}, {}, kLsDyna};
    experiment.line = lsdyna.line = false;
    experiment.markers = lsdyna.markers = true;
    for (const PaperReferenceNeedle& n : read_paper_reference(reference_file)) {
      if (!is_paper_needle(n.name)) continue;
      experiment.x.push_back(n.d_a_mm);
      experiment.y.push_back(n.deflection_experiment_mm);
      lsdyna.x.push_back(n.d_a_mm);
      lsdyna.y.push_back(n.deflection_lsdyna_mm);
      if (std::isfinite(n.sample_length_mm)) {
        measured_sample.x.push_back(n.d_a_mm);
        measured_sample.y.push_back(n.sample_length_mm);
      }
    }
    sample.series.push_back(measured_sample);
    deflection.series.push_back(experiment);
    deflection.series.push_back(lsdyna);
  }
  write_plot(dir / fmt::format("deflection_vs_{}.png", variable), deflection);
  write_plot(dir / fmt::format("groove_fill_vs_{}.png", variable), fill);
  // Only where a case fired the cannula (write_plot draws nothing without a finite point of this toolkit's).
  if (std::any_of(rows.begin(), rows.end(), [](const CaseResult& r) { return std::isfinite(r.sample_I_s_mm); }))
    write_plot(dir / fmt::format("sample_length_vs_{}.png", variable), sample);
}

// Maps of deflection and groove fill over a grid of two numeric variables (x the first, y the second).
void map_over(const fs::path& dir, const std::string& x_name, const std::string& y_name, const std::vector<CaseResult>& rows) {
  std::vector<double> xs, ys;
  for (const CaseResult& r : rows) {
    xs.push_back(r.values.at(x_name).get<double>());
    ys.push_back(r.values.at(y_name).get<double>());
  }
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  std::sort(ys.begin(), ys.end());
  ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
  HeatMap deflection;
  deflection.title = fmt::format("Tip deflection (mm) over {} and {}", x_name, y_name);
  deflection.x_label = x_name;
  deflection.y_label = y_name;
  deflection.x = xs;
  deflection.y = ys;
  deflection.values.assign(ys.size(), std::vector<double>(xs.size(), std::nan("")));
  HeatMap fill = deflection;
  fill.title = fmt::format("Groove fill over {} and {} (white: filled)", x_name, y_name);
  fill.value_format = "{:.2f}";
  fill.centre = 1.0;
  for (const CaseResult& r : rows) {
    if (r.status != "finished") continue;
    const size_t i = static_cast<size_t>(std::lower_bound(xs.begin(), xs.end(), r.values.at(x_name).get<double>()) - xs.begin());
    const size_t j = static_cast<size_t>(std::lower_bound(ys.begin(), ys.end(), r.values.at(y_name).get<double>()) - ys.begin());
    deflection.values[j][i] = r.deflection_mm;
    fill.values[j][i] = r.groove_fill;
  }
  for (const auto& [name, map] : {std::pair<std::string, const HeatMap*>{"deflection_map.png", &deflection}, {"groove_fill_map.png", &fill}}) {
    bool any = false;
    for (const auto& row : map->values) any = any || std::any_of(row.begin(), row.end(), [](double v) { return std::isfinite(v); });
    if (!any) continue;
    const RgbImage image = draw_heat_map(*map);
    write_file_atomically((dir / name).string(), [&](const std::string& scratch) { write_png(image, scratch); });
  }
}

}  // namespace

std::vector<CaseResult> collect_case_records(const fs::path& dir, const std::vector<SweepCase>& cases) {
  std::vector<CaseResult> rows;
  for (const SweepCase& c : cases) {
    const fs::path file = case_folder(dir, c.name) / "case.json";
    CaseResult r;
    if (fs::exists(file)) r = case_result_from_json(read_json_file(file.string(), "case record"), file.string());
    if (!fs::exists(file) || r.values != c.values) {
      r = CaseResult{};
      r.values = c.values;
    }
    r.index = c.index;
    r.name = c.name;
    r.label = c.label;
    rows.push_back(r);
  }
  return rows;
}

std::vector<DeflectionZero> deflection_zeros(const std::vector<std::string>& variables, const std::vector<CaseResult>& rows) {
  std::vector<DeflectionZero> zeros;
  for (const std::string& variable : variables) {
    if (!numeric_variable(rows, variable)) continue;
    for (const auto& [others, curve] : curves_along(rows, variable)) {
      std::vector<const CaseResult*> done;
      for (const CaseResult* r : curve)
        if (r->status == "finished" && std::isfinite(r->deflection_mm)) done.push_back(r);
      for (size_t k = 0; k < done.size(); ++k) {
        const double x1 = done[k]->values.at(variable).get<double>(), d1 = done[k]->deflection_mm;
        if (d1 == 0) zeros.push_back({variable, x1, others});  // a case that went straight
        if (k == 0) continue;
        const double x0 = done[k - 1]->values.at(variable).get<double>(), d0 = done[k - 1]->deflection_mm;
        if ((d0 < 0 && d1 > 0) || (d0 > 0 && d1 < 0)) zeros.push_back({variable, x0 + (x1 - x0) * d0 / (d0 - d1), others});
      }
    }
  }
  return zeros;
}

SweepCounts count_cases(const std::vector<CaseResult>& rows) {
  SweepCounts c;
  for (const CaseResult& r : rows) {
    if (r.status == "finished") ++c.finished;
    else if (r.status == "timed_out") ++c.timed_out;
    else if (r.status == "stopped") ++c.stopped;
    else if (r.status == "infeasible") ++c.infeasible;
    else if (r.status == "failed") ++c.failed;
    else ++c.pending;
  }
  return c;
}

void write_sweep_table(const fs::path& dir, const SweepPlan& plan, const std::vector<CaseResult>& rows, const std::string& reference_file) {
  std::set<std::string> force_columns;
  bool sampled = false;  // a case fired the cannula: the sample's length is a column
  for (const CaseResult& r : rows) {
    for (const auto& [column, value] : r.end_forces_N) force_columns.insert(column);
    sampled = sampled || std::isfinite(r.sample_I_s_mm);
  }
  write_file_atomically((dir / "sweep.csv").string(), [&](const std::string& scratch) {
    std::ofstream out(scratch);
    out << "case,name";
    for (const std::string& v : plan.variables) out << "," << csv_field(v);
    out << ",label,status,deflection_mm,groove_fill" << (sampled ? ",sample_I_s_mm" : "")
        << ",insertion_mm,runtime_s,max_energy_balance_error,max_penetration_mm,particles_inside";
    for (const std::string& f : force_columns) out << ",end_" << f;
    out << ",run_folder,reason\n";
    for (const CaseResult& r : rows) {
      out << r.index << "," << r.name;
      for (const std::string& v : plan.variables) out << "," << (r.values.contains(v) ? value_field(r.values.at(v)) : "");
      out << "," << csv_field(r.label) << "," << r.status << "," << number_field(r.deflection_mm) << "," << number_field(r.groove_fill) << ","
          << (sampled ? number_field(r.sample_I_s_mm) + "," : "") << number_field(r.insertion_mm) << "," << number_field(r.runtime_s) << "," << number_field(r.max_energy_balance_error) << ","
          << number_field(r.max_penetration_mm) << "," << (r.particles_inside >= 0 ? std::to_string(r.particles_inside) : "");
      for (const std::string& f : force_columns) out << "," << (r.end_forces_N.count(f) ? number_field(r.end_forces_N.at(f)) : "");
      out << "," << csv_field(r.run_folder) << "," << csv_field(r.reason) << "\n";
    }
    NEEDLE_REQUIRE(out.good(), "cannot write " + scratch);
  });
  const SweepCounts counts = count_cases(rows);
  json zeros = json::array();
  for (const DeflectionZero& z : deflection_zeros(plan.variables, rows)) zeros.push_back({{"variable", z.variable}, {"value", z.value}, {"others", z.others}});
  json cases = json::array();
  for (const CaseResult& r : rows) cases.push_back(case_result_to_json(r));
  const json table{{"sweep_file", plan.source},
                   {"design", plan.design},
                   {"variables", plan.variables},
                   {"counts",
                    {{"cases", rows.size()}, {"finished", counts.finished}, {"stopped", counts.stopped}, {"infeasible", counts.infeasible},
                     {"timed_out", counts.timed_out}, {"failed", counts.failed}, {"pending", counts.pending}}},
                   {"deflection_zero_crossings", zeros},
                   {"provenance", provenance_json()},  // the code that wrote the table (each run's summary names its own)
                   {"cases", cases}};
  write_file_atomically((dir / "sweep.json").string(), [&](const std::string& scratch) { std::ofstream(scratch) << table.dump(2) << "\n"; });
  if (!plan.variables.empty() && numeric_variable(rows, plan.variables.front()) && plan.design == "grid")
    plot_against(dir, plan.variables.front(), rows, reference_file);
  if (plan.variables.size() == 2 && numeric_variable(rows, plan.variables[0]) && numeric_variable(rows, plan.variables[1]) && plan.design == "grid")
    map_over(dir, plan.variables[0], plan.variables[1], rows);
}

}  // namespace needle
