#include "sweeps/sweep_plan.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <numeric>
#include <random>
#include <set>

#include "core/input_error.h"
#include "core/provenance.h"
#include "geometry/mesh_io.h"
#include "runs/json_file.h"

namespace needle {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr int kMaxCases = 10000;

struct VariableSpec {
  std::string name;
  std::vector<json> values;  // a list, or a range's points (grid)
  double from = 0, to = 0;   // a range's ends
  bool range = false;
};

int count_of(const JsonDocument& doc, const json& spec, const std::string& pointer) {
  const json& c = spec.at("count");
  NEEDLE_REQUIRE(c.is_number_integer() && c.get<long>() >= 1 && c.get<long>() <= kMaxCases,
                 fmt::format("{}: 'count' must be a whole number from 1 to {} (got {})", doc.where(pointer + "/count"), kMaxCases, c.dump()));
  return c.get<int>();
}

VariableSpec read_variable(const JsonDocument& doc, const std::string& name, const json& spec, bool hypercube) {
  const std::string pointer = "/variables/" + json_pointer_token(name);
  check_variable_name(name, doc.where(pointer));
  VariableSpec v;
  v.name = name;
  if (spec.is_array()) {
    NEEDLE_REQUIRE(!hypercube, fmt::format("{}: a Latin hypercube samples ranges: give '{}' as {{\"from\": a, \"to\": b}}", doc.where(pointer), name));
    NEEDLE_REQUIRE(!spec.empty(), fmt::format("{}: '{}' is an empty list: give at least one value", doc.where(pointer), name));
    for (const json& value : spec) {
      NEEDLE_REQUIRE(value.is_number() || (value.is_string() && !is_tip_variable(name)) || value.is_boolean(),
                     fmt::format("{}: '{}' values must be numbers (got {})", doc.where(pointer), name, value.dump()));
      // The same value twice would run the same case twice (1 and 1.0 are one value).
      NEEDLE_REQUIRE(std::none_of(v.values.begin(), v.values.end(), [&](const json& w) { return w == value; }),
                     fmt::format("{}: '{}' lists {} twice: give each value once", doc.where(pointer), name, value.dump()));
      v.values.push_back(value);
    }
    return v;
  }
  NEEDLE_REQUIRE(spec.is_object(), fmt::format("{}: give '{}' as a list [a, b, ...] or a range {{\"from\": a, \"to\": b, \"count\": n}}",
                                               doc.where(pointer), name));
  refuse_unknown_keys(doc, spec, pointer, {"from", "to", "count"});
  NEEDLE_REQUIRE(spec.contains("from") && spec.contains("to") && spec.at("from").is_number() && spec.at("to").is_number(),
                 fmt::format("{}: the range of '{}' needs numbers 'from' and 'to'", doc.where(pointer), name));
  v.range = true;
  v.from = spec.at("from").get<double>();
  v.to = spec.at("to").get<double>();
  if (hypercube) {
    NEEDLE_REQUIRE(!spec.contains("count"), fmt::format("{}: a Latin hypercube sets the count ('samples'): leave out 'count' of '{}'", doc.where(pointer), name));
    NEEDLE_REQUIRE(v.from != v.to, fmt::format("{}: the range of '{}' is empty (from = to = {:g})", doc.where(pointer), name, v.from));
    return v;
  }
  NEEDLE_REQUIRE(spec.contains("count"), fmt::format("{}: the range of '{}' needs 'count', the number of values from 'from' to 'to'", doc.where(pointer), name));
  const int count = count_of(doc, spec, pointer);
  NEEDLE_REQUIRE(count > 1 || v.from == v.to, fmt::format("{}: 'count' 1 gives one value: make 'from' and 'to' equal, or count at least 2", doc.where(pointer)));
  NEEDLE_REQUIRE(count == 1 || v.from != v.to, fmt::format("{}: the range of '{}' is empty (from = to = {:g}) but count is {}", doc.where(pointer), name, v.from, count));
  // Each point to 15 significant digits, so that -0.4 + 0.1 is written -0.3 (not -0.30000000000000004).
  for (int k = 0; k < count; ++k)
    v.values.push_back(k == count - 1 ? v.to : std::stod(fmt::format("{:.15g}", v.from + (v.to - v.from) * k / (count - 1))));
  return v;
}

// A uniform number in [0, 1) from the generator's 53 high bits (the same on every platform, unlike std's distributions).
double unit_uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// "design": {"cases": [{"label": "...", "variable": value, ...}, ...]}: each case sets its own variables (over "set").
SweepPlan read_explicit_cases(const JsonDocument& doc, SweepPlan plan) {
  const json& d = doc.value.at("design");
  NEEDLE_REQUIRE(d.size() == 1 && d.at("cases").is_array() && !d.at("cases").empty() && d.at("cases").size() <= kMaxCases,
                 fmt::format("{}: 'cases' must be a list of 1 to {} cases, each an object of variables and an optional label", doc.where("/design"), kMaxCases));
  NEEDLE_REQUIRE(!doc.value.contains("variables"), fmt::format("{}: explicit cases set their own variables: leave out 'variables'", doc.where("/variables")));
  std::set<std::string> names;
  for (size_t k = 0; k < d.at("cases").size(); ++k) {
    const std::string pointer = fmt::format("/design/cases/{}", k);
    const json& entry = d.at("cases").at(k);
    NEEDLE_REQUIRE(entry.is_object(), fmt::format("{}: a case is an object of variables, e.g. {{\"label\": \"stiff\", \"tissue.material.E_MPa\": 50}}", doc.where(pointer)));
    SweepCase c;
    c.index = static_cast<int>(k);
    for (const auto& item : entry.items()) {
      const std::string where = doc.where(pointer + "/" + json_pointer_token(item.key()));
      if (item.key() == "label") {
        NEEDLE_REQUIRE(item.value().is_string(), fmt::format("{}: 'label' must be a string", where));
        c.label = item.value().get<std::string>();
        continue;
      }
      check_variable_name(item.key(), where);
      NEEDLE_REQUIRE(item.value().is_number() || item.value().is_boolean() || item.value().is_array() || (item.value().is_string() && !is_tip_variable(item.key())),
                     fmt::format("{}: '{}' must be a number (got {})", where, item.key(), item.value().dump()));
      c.values[item.key()] = item.value();
      names.insert(item.key());
    }
    c.name = fmt::format("case_{:04d}", c.index);
    plan.cases.push_back(c);
  }
  plan.variables.assign(names.begin(), names.end());
  plan.design = "cases";
  return plan;
}

}  // namespace

SweepPlan read_sweep_file(const std::string& path) {
  const JsonDocument doc = read_json_with_lines(path);
  SweepPlan plan;
  plan.source = path;
  plan.base = read_design_base(doc);
  const json& v = doc.value;
  refuse_unknown_keys(doc, v, "", {"base", "model", "set", "variables", "design"});
  if (v.contains("design") && v.at("design").is_object() && v.at("design").contains("cases")) return read_explicit_cases(doc, std::move(plan));
  NEEDLE_REQUIRE(v.contains("variables") && v.at("variables").is_object() && !v.at("variables").empty(),
                 fmt::format("{}: give 'variables': an object of design variables, e.g. {{\"d_a_mm\": {{\"from\": -0.4, \"to\": 0.5, \"count\": 10}}}}",
                             doc.where("/variables")));
  bool hypercube = false;
  int samples = 0;
  unsigned long long seed = 1;
  if (v.contains("design")) {
    const json& d = v.at("design");
    if (d.is_string()) {
      NEEDLE_REQUIRE(d == "grid", fmt::format("{}: design must be \"grid\" or {{\"latin_hypercube\": {{\"samples\": n, \"seed\": s}}}}", doc.where("/design")));
    } else {
      NEEDLE_REQUIRE(d.is_object() && d.size() == 1 && d.contains("latin_hypercube") && d.at("latin_hypercube").is_object(),
                     fmt::format("{}: design must be \"grid\" or {{\"latin_hypercube\": {{\"samples\": n, \"seed\": s}}}}", doc.where("/design")));
      const json& lhs = d.at("latin_hypercube");
      refuse_unknown_keys(doc, lhs, "/design/latin_hypercube", {"samples", "seed"});
      NEEDLE_REQUIRE(lhs.contains("samples") && lhs.at("samples").is_number_integer() && lhs.at("samples").get<long>() >= 1 &&
                         lhs.at("samples").get<long>() <= kMaxCases,
                     fmt::format("{}: 'samples' must be a whole number from 1 to {}", doc.where("/design/latin_hypercube"), kMaxCases));
      if (lhs.contains("seed")) {
        NEEDLE_REQUIRE(lhs.at("seed").is_number_unsigned(), fmt::format("{}: 'seed' must be a whole number >= 0", doc.where("/design/latin_hypercube/seed")));
        seed = lhs.at("seed").get<unsigned long long>();
      }
      hypercube = true;
      samples = lhs.at("samples").get<int>();
    }
  }
  std::vector<VariableSpec> specs;
  for (const auto& item : v.at("variables").items()) specs.push_back(read_variable(doc, item.key(), item.value(), hypercube));
  for (const VariableSpec& s : specs) {
    // A d_a_mm variable grinds the paper's multi-bevel family: over a multi-bevel preset (LMB, AMB, HMB: the same
    // angles) it moves A; over SB or a recipe file it would replace the base's needle in silence, so it is refused.
    const bool multi_bevel_base = plan.base.preset == "LMB" || plan.base.preset == "AMB" || plan.base.preset == "HMB";
    NEEDLE_REQUIRE(s.name != "d_a_mm" || multi_bevel_base || (plan.base.preset.empty() && plan.base.recipe_file.empty()),
                   fmt::format("{}: a 'd_a_mm' variable grinds the paper's multi-bevel tips, which would replace the base's {}: leave "
                               "that out of 'base', or give a multi-bevel base (preset LMB, AMB or HMB, or base.d_a_mm)",
                               doc.where("/variables/d_a_mm"),
                               plan.base.preset.empty() ? "recipe" : fmt::format("preset {}", plan.base.preset)));
    NEEDLE_REQUIRE(!plan.base.settings.contains(s.name),
                   fmt::format("{}: '{}' is both a design variable and a fixed key of 'set'", doc.where("/variables/" + json_pointer_token(s.name)), s.name));
    plan.variables.push_back(s.name);
  }
  if (hypercube) {
    plan.design = fmt::format("latin hypercube, {} samples, seed {}", samples, seed);
    std::mt19937_64 rng(seed);
    std::vector<std::vector<double>> columns;
    for (const VariableSpec& s : specs) {
      std::vector<int> slot(samples);
      std::iota(slot.begin(), slot.end(), 0);
      for (int k = samples - 1; k > 0; --k) std::swap(slot[k], slot[static_cast<int>(rng() % static_cast<unsigned long long>(k + 1))]);
      std::vector<double> column(samples);
      for (int k = 0; k < samples; ++k) column[k] = s.from + (s.to - s.from) * (slot[k] + unit_uniform(rng)) / samples;
      columns.push_back(column);
    }
    for (int k = 0; k < samples; ++k) {
      SweepCase c;
      c.index = k;
      for (size_t j = 0; j < specs.size(); ++j) c.values[specs[j].name] = columns[j][k];
      plan.cases.push_back(c);
    }
  } else {
    plan.design = "grid";
    double total = 1;
    for (const VariableSpec& s : specs) total *= static_cast<double>(s.values.size());
    NEEDLE_REQUIRE(total <= kMaxCases, fmt::format("{}: the grid makes {:.0f} cases; the limit is {}", doc.where("/variables"), total, kMaxCases));
    std::vector<size_t> at(specs.size(), 0);
    for (int k = 0; k < static_cast<int>(total); ++k) {
      SweepCase c;
      c.index = k;
      for (size_t j = 0; j < specs.size(); ++j) c.values[specs[j].name] = specs[j].values[at[j]];
      plan.cases.push_back(c);
      for (size_t j = specs.size(); j-- > 0;) {  // the last variable fastest
        if (++at[j] < specs[j].values.size()) break;
        at[j] = 0;
      }
    }
  }
  for (SweepCase& c : plan.cases) c.name = fmt::format("case_{:04d}", c.index);
  return plan;
}

json sweep_plan_to_json(const SweepPlan& plan) {
  json cases = json::array();
  for (const SweepCase& c : plan.cases) {
    cases.push_back({{"case", c.index}, {"name", c.name}, {"variables", c.values}});
    if (!c.label.empty()) cases.back()["label"] = c.label;
  }
  json j = design_base_to_json(plan.base);
  j["design"] = plan.design;
  j["variables"] = plan.variables;
  j["cases"] = cases;
  return j;
}

std::map<int, std::string> check_sweep_cases(const SweepPlan& plan) {
  std::map<int, std::string> infeasible;
  for (const SweepCase& c : plan.cases) {
    CaseSetup setup;
    try {
      setup = case_setup(plan.base, c.values);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {} ({}): {}", plan.source, c.name, describe_values(c.values), e.what()));
    }
    const std::string reason = tip_infeasibility(setup);
    if (!reason.empty()) infeasible[c.index] = reason;
  }
  NEEDLE_REQUIRE(infeasible.size() < plan.cases.size() || plan.cases.empty(),
                 fmt::format("{}: no case of the sweep has a tip that can be ground; the first: {} ({}): {}", plan.source,
                             plan.cases.front().name, describe_values(plan.cases.front().values), infeasible.begin()->second));
  return infeasible;
}

bool plan_extends(const json& plan, const json& stored) {
  const auto is_prefix = [](const json& shorter, const json& longer) {
    return shorter.is_array() && longer.is_array() && shorter.size() <= longer.size() && std::equal(shorter.begin(), shorter.end(), longer.begin());
  };
  if (!plan.is_object() || !stored.is_object() || !plan.contains("cases") || !stored.contains("cases") ||
      !is_prefix(stored["cases"], plan["cases"]))
    return false;
  json rest = plan, stored_rest = stored;
  rest.erase("cases");
  stored_rest.erase("cases");
  // A listed design ({"cases": [...]}) holds the cases again: they too may only grow at the end.
  const auto listed = [](const json& j) { return j.contains("design") && j["design"].is_object() && j["design"].contains("cases"); };
  if (listed(rest) && listed(stored_rest)) {
    if (!is_prefix(stored_rest["design"]["cases"], rest["design"]["cases"])) return false;
    rest["design"].erase("cases");
    stored_rest["design"].erase("cases");
  }
  return rest == stored_rest;
}

void claim_study_folder(const fs::path& dir, const std::string& stored_name, const json& plan, bool allow_other_code) {
  const fs::path file = dir / stored_name;
  const fs::path code_file = dir / kStudyCodeFile;
  // The code that runs the study's cases: a study goes on only with the code that began it, unless told otherwise.
  const auto check_code = [&] {
    if (!fs::exists(code_file)) {
      write_file_atomically(code_file.string(), [&](const std::string& scratch) { std::ofstream(scratch) << provenance_line() << "\n"; });
      return;
    }
    std::ifstream in(code_file);
    std::string began;
    std::getline(in, began);
    NEEDLE_REQUIRE(allow_other_code || began == provenance_line(),
                   fmt::format("--out {}: its cases were run by {}; this is {}: one table would mix two codes' results. Give a new --out, "
                               "or --allow-other-code to go on with this one",
                               dir.string(), began, provenance_line()));
  };
  if (fs::exists(dir)) {
    NEEDLE_REQUIRE(fs::is_directory(dir), fmt::format("--out {}: exists and is not a folder", dir.string()));
    if (fs::exists(file)) {
      const json stored = read_json_file(file.string(), "study plan");
      const bool extended = stored != plan && plan_extends(plan, stored);
      NEEDLE_REQUIRE(stored == plan || extended,
                     fmt::format("--out {}: holds another study (its {} differs from this file's cases); give a new --out", dir.string(), stored_name));
      check_code();
      if (extended) write_file_atomically(file.string(), [&](const std::string& scratch) { std::ofstream(scratch) << plan.dump(2) << "\n"; });
      return;
    }
    // Empty, or only what another worker of the same study is writing just now (a Slurm array's tasks start together).
    bool only_study_files = true;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
      const std::string name = entry.path().filename().string();
      only_study_files = only_study_files && (name == "cases" || name == kStudyCodeFile || name.rfind(".needle-partial-", 0) == 0);
    }
    NEEDLE_REQUIRE(only_study_files, fmt::format("--out {}: is a folder that is not a study of the toolkit (no {}); give a new or empty one",
                                                  dir.string(), stored_name));
  } else {
    NEEDLE_REQUIRE(dir.parent_path().empty() || fs::is_directory(fs::absolute(dir).parent_path()),
                   fmt::format("--out {}: its parent folder does not exist", dir.string()));
    fs::create_directories(dir);
  }
  write_file_atomically(file.string(), [&](const std::string& scratch) { std::ofstream(scratch) << plan.dump(2) << "\n"; });
  check_code();
}

}  // namespace needle
