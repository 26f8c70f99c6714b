#include "sweeps/stress_report.h"

#include <cmath>
#include <fmt/format.h>
#include <fstream>

#include "geometry/mesh_io.h"

namespace needle {
namespace fs = std::filesystem;

namespace {
std::string cell(double x, const char* format) { return std::isfinite(x) ? fmt::format(fmt::runtime(format), x) : "n/a"; }
std::string escaped(std::string text) {
  for (char& c : text)
    if (c == '|' || c == '\n') c = ' ';
  return text;
}
}  // namespace

std::string stress_finding(const CaseResult& r) {
  if (r.status == "pending") return "not run";
  if (r.status == "failed") return "failed: " + r.reason;
  if (r.status == "timed_out") return "a hang or a crawl: " + r.reason;
  if (r.status == "finished" && !(std::isfinite(r.deflection_mm) && std::isfinite(r.max_energy_balance_error) && std::isfinite(r.max_penetration_mm)))
    return "finished with a number that is not finite";
  if (r.status == "stopped" && r.reason.empty()) return "stopped without a reason";
  return "";
}

int write_stress_report(const fs::path& dir, const std::string& suite_file, const std::vector<CaseResult>& rows) {
  int findings = 0;
  std::string table = fmt::format(
      "# Hard-case suite: {}\n\n"
      "Each case changes one thing of the suite's base scene. A case passes when it finishes with finite numbers or the "
      "solver stops it with the monitor that fired (blow-up, penetration, energy drift, step collapse); it fails when it "
      "crashes, hangs (the time limit) or ends in a number that is not finite.\n\n"
      "| # | case | status | monitor or reason | deflection (mm) | worst energy error | deepest penetration (mm) | particles inside | runtime (s) | finding |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n",
      suite_file);
  for (const CaseResult& r : rows) {
    const std::string finding = stress_finding(r);
    findings += !finding.empty();
    table += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", r.index, escaped(r.label.empty() ? describe_values(r.values) : r.label),
                         r.status, escaped(r.reason), cell(r.deflection_mm, "{:+.4f}"), cell(100 * r.max_energy_balance_error, "{:.2f} %"),
                         cell(r.max_penetration_mm, "{:.4f}"), r.particles_inside >= 0 ? std::to_string(r.particles_inside) : "n/a",
                         cell(r.runtime_s, "{:.1f}"), finding.empty() ? "none" : escaped(finding));
  }
  table += fmt::format("\n{} of {} cases pass; {} finding(s).\n", rows.size() - static_cast<size_t>(findings), rows.size(), findings);
  write_file_atomically((dir / "stress.md").string(), [&](const std::string& scratch) { std::ofstream(scratch) << table; });
  return findings;
}

}  // namespace needle
