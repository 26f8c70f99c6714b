#include "studies/paper_results.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "runs/json_file.h"
#include "core/input_error.h"
#include "plot/line_plot.h"

namespace needle {
using json = nlohmann::json;

namespace {
const std::vector<std::string> kPaperOrder = {"SB", "LMB", "AMB", "HMB"};
}  // namespace

bool is_paper_needle(const std::string& name) { return std::find(kPaperOrder.begin(), kPaperOrder.end(), name) != kPaperOrder.end(); }

std::vector<PaperReferenceNeedle> read_paper_reference(const std::string& path) {
  const json j = read_json_file(path, "paper's reference table");
  NEEDLE_REQUIRE(j.contains("needles") && j["needles"].is_object(), fmt::format("{}: no 'needles' object", path));
  std::vector<PaperReferenceNeedle> out;
  for (const auto& item : j["needles"].items()) {
    const std::string& name = item.key();
    const json& v = item.value();
    PaperReferenceNeedle r;
    r.name = name;
    auto number = [&](const char* key) {
      NEEDLE_REQUIRE(v.contains(key) && v[key].is_number(), fmt::format("{}: needles.{}.{} must be a number", path, name, key));
      return v[key].get<double>();
    };
    r.d_a_mm = number("d_a_mm");
    r.deflection_experiment_mm = number("deflection_experiment_mm");
    r.deflection_lsdyna_mm = number("deflection_lsdyna_mm");
    r.sample_length_mm = number("sample_length_mm");
    r.groove_contact_in_model = v.value("groove_contact_in_model", std::string());
    out.push_back(r);
  }
  auto rank = [](const std::string& n) {
    const auto it = std::find(kPaperOrder.begin(), kPaperOrder.end(), n);
    return static_cast<int>(it - kPaperOrder.begin());
  };
  std::stable_sort(out.begin(), out.end(), [&](const auto& a, const auto& b) {
    return rank(a.name) != rank(b.name) ? rank(a.name) < rank(b.name) : a.name < b.name;
  });
  return out;
}

const PaperReferenceNeedle* find_reference(const std::vector<PaperReferenceNeedle>& reference, const std::string& name) {
  for (const PaperReferenceNeedle& r : reference)
    if (r.name == name) return &r;
  return nullptr;
}

std::string fmt_mm(double v, const char* f) { return std::isfinite(v) ? fmt::format(fmt::runtime(f), v) : std::string("n/a"); }

const NeedleOutcome* find_outcome(const std::vector<NeedleOutcome>& runs, const std::string& name) {
  for (const NeedleOutcome& r : runs)
    if (r.name == name) return &r;
  return nullptr;
}

std::vector<PaperTarget> evaluate_paper_targets(const std::vector<NeedleOutcome>& runs, const std::vector<PaperReferenceNeedle>& reference) {
  auto delta = [&](const char* n) { const NeedleOutcome* r = find_outcome(runs, n); return r ? r->deflection_mm : kNaN; };
  auto fill = [&](const char* n) { const NeedleOutcome* r = find_outcome(runs, n); return r ? r->groove_fill : kNaN; };
  std::vector<PaperTarget> out;
  const double sb = delta("SB"), lmb = delta("LMB"), amb = delta("AMB"), hmb = delta("HMB");
  {
    PaperTarget t{"sign and order: SB < 0 < LMB <~ AMB < HMB (<~: within 0.1 mm)",
             fmt::format("SB {} / LMB {} / AMB {} / HMB {} mm", fmt_mm(sb), fmt_mm(lmb), fmt_mm(amb), fmt_mm(hmb))};
    t.checked = std::isfinite(sb + lmb + amb + hmb);
    t.met = t.checked && sb < 0 && lmb > 0 && lmb <= amb + 0.1 && amb < hmb;
    out.push_back(t);
  }
  for (const char* n : {"SB", "LMB", "AMB"}) {
    const PaperReferenceNeedle* ref = find_reference(reference, n);
    PaperTarget t{fmt::format("{}: abs(delta - delta_experiment) <= 0.1 mm", n), "n/a"};
    t.needle = n, t.allowed_mm = 0.1, t.allowance = "0.10 mm allowed";
    if (ref && std::isfinite(delta(n))) {
      const double error = delta(n) - ref->deflection_experiment_mm;
      t.numbers = fmt::format("{} - ({:+.2f}) = {:+.3f} mm", fmt_mm(delta(n)), ref->deflection_experiment_mm, error);
      t.checked = true;
      t.met = std::abs(error) <= t.allowed_mm;
      t.error_mm = error;
    }
    out.push_back(t);
  }
  if (const PaperReferenceNeedle* ref = find_reference(reference, "HMB")) {
    const double lsdyna_error = std::abs(ref->deflection_lsdyna_mm - ref->deflection_experiment_mm);
    PaperTarget t{fmt::format("HMB: error below LS-DYNA's {:.2f} mm", lsdyna_error), "n/a"};
    t.needle = "HMB", t.allowed_mm = lsdyna_error;
    t.allowance = fmt::format("where the target is an error below LS-DYNA's own, {:.2f} mm", lsdyna_error);
    if (std::isfinite(hmb)) {
      const double error = std::abs(hmb - ref->deflection_experiment_mm);
      t.numbers = fmt::format("abs({} - ({:+.2f})) = {:.3f} mm", fmt_mm(hmb), ref->deflection_experiment_mm, error);
      t.checked = true;
      t.met = error < lsdyna_error;
      t.error_mm = hmb - ref->deflection_experiment_mm;
    }
    out.push_back(t);
  }
  {
    PaperTarget t{"groove fill ranks SB and LMB above AMB above HMB",
             fmt::format("SB {} / LMB {} / AMB {} / HMB {}", fmt_mm(fill("SB"), "{:.3f}"), fmt_mm(fill("LMB"), "{:.3f}"),
                         fmt_mm(fill("AMB"), "{:.3f}"), fmt_mm(fill("HMB"), "{:.3f}"))};
    t.checked = std::isfinite(fill("SB") + fill("LMB") + fill("AMB") + fill("HMB"));
    t.met = t.checked && std::min(fill("SB"), fill("LMB")) > fill("AMB") && fill("AMB") > fill("HMB");
    out.push_back(t);
  }
  return out;
}

Rgb compared_model_colour(int k) {
  if (k <= 0) return kOurs;
  // plot_color's palette without its blue (kOurs), orange (kLsDyna) and grey (near kExperiment).
  static const int others[] = {1, 2, 4, 5, 6};
  return plot_color(others[static_cast<size_t>(k - 1) % std::size(others)]);
}

}  // namespace needle
