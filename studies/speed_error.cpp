#include "studies/speed_error.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <limits>

#include "geometry/mesh_io.h"
#include "plot/line_plot.h"
#include "runs/json_file.h"
#include "runs/model_levels.h"
#include "runs/run_summary.h"

namespace needle {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string csv_number(double v) { return std::isfinite(v) ? fmt::format("{}", v) : ""; }
// A text field without the characters that would split or quote it.
std::string csv_text(std::string text) {
  for (char& c : text)
    if (c == ',' || c == '"' || c == '\n') c = ';';
  return text;
}
nlohmann::json json_number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

SpeedErrorCase speed_error_case(const std::string& needle, const std::string& level, const nlohmann::json& s) {
  SpeedErrorCase c;
  c.needle = needle;
  c.level = level;
  const RunOutcome o = run_outcome(s);
  c.status = o.status;
  c.reason = o.reason;
  c.runtime_s = o.runtime_s;
  c.deflection_mm = o.deflection_mm;
  c.max_penetration_mm = o.max_penetration_mm;
  c.max_energy_balance_error = o.max_energy_balance_error;
  c.coupling_steps = o.steps;
  c.needle_steps = s.value("needle_steps", 0L);
  c.max_particles_inside = s.value("max_particles_inside", 0);
  c.error_vs_reference_mm = c.error_vs_full_mm = kNaN;
  const nlohmann::json machine = s.value("machine", nlohmann::json::object());
  c.threads_used = machine.value("threads_used", 0);
  c.cores = machine.value("cores", 0);
  const auto load = [&machine](const char* key) { return machine.contains(key) && machine[key].is_number() ? machine[key].get<double>() : kNaN; };
  c.load_at_start = load("load_average_1min_at_start");
  c.load_at_end = load("load_average_1min_at_end");
  return c;
}

std::string beside_words(const SpeedErrorCase& c) {
  if (c.threads_used <= 0) return "not recorded";
  std::string words = fmt::format("{} thread{} of {} cores", c.threads_used, c.threads_used == 1 ? "" : "s", c.cores);
  if (std::isfinite(c.load_at_start) && std::isfinite(c.load_at_end))
    words += fmt::format(", load {:.1f} at the start, {:.1f} at the end", c.load_at_start, c.load_at_end);
  return words;
}

std::string speed_error_markdown(const std::vector<SpeedErrorCase>& cases, const std::string& reference_source) {
  const auto mm = [](double v) { return std::isfinite(v) ? fmt::format("{:+.4f}", v) : std::string("–"); };
  std::string md = fmt::format(
      "Each needle at each model level on the same scene; δ's error against the converged reference ({}) and against the "
      "full level's run. The load is the machine's 1-minute load average (the run's own threads count in it at the end: "
      "more than the threads used means other work ran beside).\n\n",
      reference_source);
  md += "| needle | level | δ (mm) | vs reference | vs full | coupling steps | needle steps | time (s) | beside it |\n";
  md += "|---|---|---|---|---|---|---|---|---|\n";
  for (const SpeedErrorCase& c : cases)
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {:.1f} | {} |\n", c.needle, c.level,
                      c.status == "finished" ? fmt::format("{:+.4f}", c.deflection_mm) : c.status, mm(c.error_vs_reference_mm),
                      mm(c.error_vs_full_mm), c.coupling_steps, c.needle_steps, c.runtime_s, beside_words(c));
  return md;
}

void fill_errors(std::vector<SpeedErrorCase>& cases, const nlohmann::json& reference_mm) {
  for (SpeedErrorCase& c : cases) {
    c.error_vs_reference_mm = c.error_vs_full_mm = kNaN;
    if (c.status != "finished") continue;
    if (reference_mm.contains(c.needle) && reference_mm[c.needle].is_number())
      c.error_vs_reference_mm = c.deflection_mm - reference_mm[c.needle].get<double>();
    for (const SpeedErrorCase& full : cases)
      if (full.needle == c.needle && full.level == kReferenceModelLevel && full.status == "finished") c.error_vs_full_mm = c.deflection_mm - full.deflection_mm;
  }
}

std::string speed_error_table(const std::vector<SpeedErrorCase>& cases) {
  std::string out = fmt::format("{:<7} {:<11} {:>9} {:>9} {:>10} {:>11} {:>12} {:>11} {:>10} {:>9}  {}\n", "needle", "level", "time_s",
                                "steps", "needle_st", "delta_mm", "err_ref_mm", "err_full_mm", "depth_mm", "energy_%", "status (beside it)");
  for (const SpeedErrorCase& c : cases)
    out += fmt::format("{:<7} {:<11} {:>9.1f} {:>9} {:>10} {:>11.4f} {:>12} {:>11} {:>10.3g} {:>9.3f}  {}{} ({})\n", c.needle, c.level, c.runtime_s,
                       c.coupling_steps, c.needle_steps, c.deflection_mm,
                       std::isfinite(c.error_vs_reference_mm) ? fmt::format("{:+.4f}", c.error_vs_reference_mm) : "-",
                       std::isfinite(c.error_vs_full_mm) ? fmt::format("{:+.4f}", c.error_vs_full_mm) : "-", c.max_penetration_mm,
                       100 * c.max_energy_balance_error, c.status, c.reason.empty() ? "" : ": " + c.reason, beside_words(c));
  return out;
}

void write_speed_error_report(const std::vector<SpeedErrorCase>& cases, const std::string& folder, const std::string& reference_source) {
  const std::filesystem::path dir(folder);
  write_file_atomically((dir / "speed_error.csv").string(), [&](const std::string& scratch) {
    std::ofstream f(scratch);
    f << "needle,level,runtime_s,coupling_steps,needle_steps,deflection_mm,error_vs_reference_mm,error_vs_full_mm,max_penetration_mm,"
         "max_particles_inside,max_energy_balance_error,status,reason,threads_used,cores,load_average_1min_at_start,load_average_1min_at_end\n";
    for (const SpeedErrorCase& c : cases)
      f << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", c.needle, c.level, csv_number(c.runtime_s), c.coupling_steps,
                       c.needle_steps, csv_number(c.deflection_mm), csv_number(c.error_vs_reference_mm), csv_number(c.error_vs_full_mm),
                       csv_number(c.max_penetration_mm), c.max_particles_inside, csv_number(c.max_energy_balance_error), c.status,
                       csv_text(c.reason), c.threads_used, c.cores, csv_number(c.load_at_start), csv_number(c.load_at_end));
  });
  nlohmann::json j = {{"reference", reference_source}, {"cases", nlohmann::json::array()}};
  for (const SpeedErrorCase& c : cases)
    j["cases"].push_back({{"needle", c.needle}, {"level", c.level}, {"runtime_s", json_number(c.runtime_s)}, {"coupling_steps", c.coupling_steps},
                          {"needle_steps", c.needle_steps}, {"deflection_mm", json_number(c.deflection_mm)},
                          {"error_vs_reference_mm", json_number(c.error_vs_reference_mm)}, {"error_vs_full_mm", json_number(c.error_vs_full_mm)},
                          {"max_penetration_mm", json_number(c.max_penetration_mm)}, {"max_particles_inside", c.max_particles_inside},
                          {"max_energy_balance_error", json_number(c.max_energy_balance_error)}, {"status", c.status}, {"reason", c.reason},
                          {"threads_used", c.threads_used}, {"cores", c.cores}, {"load_average_1min_at_start", json_number(c.load_at_start)},
                          {"load_average_1min_at_end", json_number(c.load_at_end)}});
  write_file_atomically((dir / "speed_error.json").string(), [&](const std::string& scratch) { std::ofstream(scratch) << j.dump(2) << "\n"; });
  write_file_atomically((dir / "speed_error.md").string(), [&](const std::string& scratch) { std::ofstream(scratch) << speed_error_markdown(cases, reference_source); });
  // Time against |error vs the reference|, one series of points per needle (levels in the order run).
  LinePlot plot;
  plot.title = "Speed against error: each model level (time, |deflection - reference|)";
  plot.x_label = "run time (s)";
  plot.y_label = "|deflection error| vs reference (mm)";
  std::vector<std::string> needles;
  for (const SpeedErrorCase& c : cases)
    if (std::find(needles.begin(), needles.end(), c.needle) == needles.end()) needles.push_back(c.needle);
  for (size_t k = 0; k < needles.size(); ++k) {
    PlotSeries s;
    s.label = needles[k];
    s.color = plot_color(static_cast<int>(k));
    s.markers = true;
    for (const SpeedErrorCase& c : cases)
      if (c.needle == needles[k] && std::isfinite(c.error_vs_reference_mm) && std::isfinite(c.runtime_s)) {
        s.x.push_back(c.runtime_s);
        s.y.push_back(std::abs(c.error_vs_reference_mm));
        s.label += (s.x.size() == 1 ? ": " : ", ") + c.level;
      }
    if (!s.x.empty()) plot.series.push_back(s);
  }
  if (!plot.series.empty())
    write_file_atomically((dir / "speed_error.png").string(), [&](const std::string& scratch) { write_png(draw_line_plot(plot), scratch); });
}

}  // namespace needle
