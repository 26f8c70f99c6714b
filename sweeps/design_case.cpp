#include "sweeps/design_case.h"

#include <algorithm>
#include <chrono>
#include <fmt/format.h>
#include <fstream>

#include "core/input_error.h"
#include "geometry/mesh_io.h"
#include "geometry/tip_geometry.h"
#include "runs/csv_table.h"
#include "runs/insertion_run.h"
#include "runs/scene_request.h"
#include "runs/json_file.h"
#include "runs/model_levels.h"
#include "runs/recipe_json.h"
#include "runs/run_summary.h"

namespace needle {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// A path in a study file, taken relative to the study file's folder.
std::string path_beside(const std::string& study_file, const std::string& path) {
  if (path.empty()) return path;
  const fs::path p(path);
  return fs::absolute(p.is_absolute() ? p : fs::path(study_file).parent_path() / p).lexically_normal().string();
}

std::string text_of(const JsonDocument& doc, const json& object, const std::string& key, const std::string& pointer) {
  if (!object.contains(key)) return "";
  NEEDLE_REQUIRE(object.at(key).is_string(), fmt::format("{}: '{}' must be a string", doc.where(pointer + "/" + key), key));
  return object.at(key).get<std::string>();
}

// A value as --set reads it: text as itself, anything else as JSON.
std::string setting_text(const json& value) { return value.is_string() ? value.get<std::string>() : value.dump(); }

// d_a of the scene's needle, for a case that varies the tip's angles but not d_a.
double base_d_a(const NeedleScene& needle) {
  if (std::isfinite(needle.d_a_mm)) return needle.d_a_mm;
  if (needle.preset == "LMB" || needle.preset == "AMB" || needle.preset == "HMB") return *resolve_tip(preset_recipe(needle.preset)).d_a_mm();
  throw InputError(
      "the tip angles (top_tilt_deg, bevel_tilt_deg, side_rotation_deg) shape a multi-bevel tip: give d_a_mm as a variable, "
      "or a multi-bevel base needle (base.d_a_mm, or base.preset LMB, AMB or HMB)");
}

// The recipe the scene's needle is ground by (none for a mesh file or a plain rod).
std::optional<GrindingRecipe> scene_recipe(const NeedleScene& n) {
  if (!n.mesh_file.empty() || n.plain_rod) return std::nullopt;
  GrindingRecipe recipe = !n.preset.empty() ? preset_recipe(n.preset)
                          : !n.recipe_file.empty() ? read_recipe_file(n.recipe_file)
                          : std::isfinite(n.d_a_mm) ? multi_bevel_recipe(n.d_a_mm)
                                                    : preset_recipe("SB");
  return recipe;
}

}  // namespace

void refuse_unknown_keys(const JsonDocument& doc, const json& object, const std::string& pointer, const std::vector<std::string>& known) {
  for (const auto& item : object.items()) {
    if (std::find(known.begin(), known.end(), item.key()) != known.end()) continue;
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
    throw InputError(fmt::format("{}: unknown key '{}' (known: {})", doc.where(pointer + "/" + json_pointer_token(item.key())), item.key(), list));
  }
}

DesignBase read_design_base(const JsonDocument& doc) {
  DesignBase b;
  const json& v = doc.value;
  NEEDLE_REQUIRE(v.is_object(), fmt::format("{}: a study file is a JSON object (docs/sweeps.md)", doc.source));
  if (v.contains("base")) {
    const json& base = v.at("base");
    NEEDLE_REQUIRE(base.is_object(), fmt::format("{}: 'base' must be an object: scene, preset, d_a_mm, recipe, calibration", doc.where("/base")));
    refuse_unknown_keys(doc, base, "/base", {"scene", "preset", "d_a_mm", "recipe", "calibration"});
    b.scene_file = path_beside(doc.source, text_of(doc, base, "scene", "/base"));
    b.preset = text_of(doc, base, "preset", "/base");
    b.recipe_file = path_beside(doc.source, text_of(doc, base, "recipe", "/base"));
    b.calibration_file = path_beside(doc.source, text_of(doc, base, "calibration", "/base"));
    if (base.contains("d_a_mm")) {
      NEEDLE_REQUIRE(base.at("d_a_mm").is_number(), fmt::format("{}: 'd_a_mm' must be a number (mm)", doc.where("/base/d_a_mm")));
      b.d_a_mm = base.at("d_a_mm").get<double>();
    }
    const int sources = !b.preset.empty() + !b.recipe_file.empty() + std::isfinite(b.d_a_mm);
    NEEDLE_REQUIRE(sources <= 1, fmt::format("{}: give at most one needle: preset, d_a_mm or recipe", doc.where("/base")));
  }
  if (v.contains("model")) b.model = text_of(doc, v, "model", "");
  if (v.contains("set")) {
    NEEDLE_REQUIRE(v.at("set").is_object(), fmt::format("{}: 'set' must be an object of dotted scene keys, e.g. {{\"motion.travel_mm\": 10}}",
                                                        doc.where("/set")));
    for (const auto& item : v.at("set").items()) {
      NEEDLE_REQUIRE(item.key().find('.') != std::string::npos && !is_tip_variable(item.key()),
                     fmt::format("{}: '{}' is not a dotted scene key (e.g. motion.travel_mm; docs/scenes.md)",
                                 doc.where("/set/" + json_pointer_token(item.key())), item.key()));
    }
    b.settings = v.at("set");
  }
  return b;
}

json design_base_to_json(const DesignBase& b) {
  json j = json::object();
  if (!b.scene_file.empty()) j["scene"] = b.scene_file;
  if (!b.preset.empty()) j["preset"] = b.preset;
  if (!b.recipe_file.empty()) j["recipe"] = b.recipe_file;
  if (std::isfinite(b.d_a_mm)) j["d_a_mm"] = b.d_a_mm;
  if (!b.calibration_file.empty()) j["calibration"] = b.calibration_file;
  return json{{"base", j}, {"model", b.model}, {"set", b.settings}};
}

const std::vector<std::string>& tip_variable_names() {
  static const std::vector<std::string> names = {"d_a_mm", "top_tilt_deg", "bevel_tilt_deg", "side_rotation_deg"};
  return names;
}

bool is_tip_variable(const std::string& name) {
  const auto& names = tip_variable_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

void check_variable_name(const std::string& name, const std::string& where) {
  NEEDLE_REQUIRE(is_tip_variable(name) || (name.find('.') != std::string::npos && name.front() != '.' && name.back() != '.'),
                 fmt::format("{}: unknown design variable '{}' (the tip's: d_a_mm, top_tilt_deg, bevel_tilt_deg, side_rotation_deg; "
                             "or any dotted scene key, e.g. tissue.friction or needle.groove_start_mm)",
                             where, name));
}

CaseSetup case_setup(const DesignBase& b, const json& values) {
  // The case's scene as `needle run` resolves it (runs/scene_request.h): the study's base, then its "set" keys and the
  // case's variables, read together last; the tissue's E from the base's calibration, or the shipped one of the model
  // level the case's scene has.
  SceneRequest request;
  request.scene_file = b.scene_file;
  request.preset = b.preset;
  request.d_a_mm = std::isfinite(b.d_a_mm) ? b.d_a_mm : std::nan("");
  request.recipe_file = b.recipe_file;
  request.model = b.model;
  request.model_where = "model";
  request.calibration_file = b.calibration_file;
  std::vector<NamedSceneSetting> settings;
  for (const auto& item : b.settings.items()) {
    const std::string setting = item.key() + "=" + setting_text(item.value());
    settings.push_back({setting, setting});  // the keys are the study file's variables and "set", not --set flags
  }
  MultiBevelAngles angles;
  bool angles_given = false;
  double d_a = std::nan("");
  for (const auto& item : values.items()) {
    const std::string& name = item.key();
    if (!is_tip_variable(name)) {
      const std::string setting = name + "=" + setting_text(item.value());
      settings.push_back({setting, setting});
      continue;
    }
    NEEDLE_REQUIRE(item.value().is_number(), fmt::format("{} must be a number (got {})", name, item.value().dump()));
    const double x = item.value().get<double>();
    if (name == "d_a_mm") d_a = x;
    if (name == "top_tilt_deg") angles.top_tilt_deg = x;
    if (name == "bevel_tilt_deg") angles.bevel_tilt_deg = x;
    if (name == "side_rotation_deg") angles.side_rotation_deg = x;
    angles_given = angles_given || name != "d_a_mm";
  }
  request.settings = settings;
  CaseSetup setup;
  setup.scene = resolve_scene(request).scene;
  NeedleScene& needle = setup.scene.needle;
  if (angles_given) {
    Rod rod;
    rod.length_mm = needle.length_mm;
    Groove groove;
    if (std::isfinite(needle.groove_start_mm)) groove.start_behind_tip_mm = needle.groove_start_mm;
    setup.recipe = multi_bevel_recipe(std::isfinite(d_a) ? d_a : base_d_a(needle), angles, rod, groove);
  } else if (std::isfinite(d_a)) {
    needle.select_source("", d_a, "");
  }
  return setup;
}

std::optional<GrindingRecipe> case_recipe(const CaseSetup& setup) {
  if (setup.recipe) return setup.recipe;
  std::optional<GrindingRecipe> recipe = scene_recipe(setup.scene.needle);
  if (recipe) recipe->rod.length_mm = setup.scene.needle.length_mm;
  if (recipe && recipe->groove && std::isfinite(setup.scene.needle.groove_start_mm)) recipe->groove->start_behind_tip_mm = setup.scene.needle.groove_start_mm;
  return recipe;
}

std::string tip_infeasibility(const CaseSetup& setup) {
  const std::optional<GrindingRecipe> recipe = case_recipe(setup);
  if (!recipe) return "";
  try {
    resolve_tip(*recipe);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

CaseResult case_record(int index, const std::string& name, const std::string& label, const json& values, const std::string& status,
                       const std::string& reason) {
  CaseResult r;
  r.index = index;
  r.name = name;
  r.label = label;
  r.values = values;
  r.status = status;
  r.reason = reason;
  return r;
}

std::string finished_case_words(const CaseResult& r) {
  std::string words = fmt::format("deflection {:+.4f} mm, groove fill {:.3f}", r.deflection_mm, r.groove_fill);
  if (std::isfinite(r.sample_I_s_mm)) words += fmt::format(", I_s {:.2f} mm", r.sample_I_s_mm);
  return words;
}

json case_result_to_json(const CaseResult& r) {
  auto number = [](double x) { return std::isfinite(x) ? json(x) : json(nullptr); };
  json j{{"case", r.index},
              {"name", r.name},
              {"variables", r.values},
              {"status", r.status},
              {"reason", r.reason},
              {"deflection_mm", number(r.deflection_mm)},
              {"groove_fill", number(r.groove_fill)},
              {"insertion_mm", number(r.insertion_mm)},
              {"runtime_s", number(r.runtime_s)},
              {"max_energy_balance_error", number(r.max_energy_balance_error)},
              {"max_penetration_mm", number(r.max_penetration_mm)},
              {"particles_inside", r.particles_inside},
              {"end_forces_N", r.end_forces_N},
              {"run_folder", r.run_folder}};
  if (!r.label.empty()) j["label"] = r.label;
  if (std::isfinite(r.sample_I_s_mm)) j["sample_I_s_mm"] = r.sample_I_s_mm;  // only where the cannula was fired
  return j;
}

CaseResult case_result_from_json(const json& j, const std::string& source) {
  try {
    CaseResult r;
    r.index = j.at("case").get<int>();
    r.name = j.at("name").get<std::string>();
    r.values = j.at("variables");
    r.status = j.at("status").get<std::string>();
    r.reason = j.at("reason").get<std::string>();
    r.deflection_mm = number_or_nan(j, "deflection_mm");
    r.groove_fill = number_or_nan(j, "groove_fill");
    r.sample_I_s_mm = number_or_nan(j, "sample_I_s_mm");
    r.insertion_mm = number_or_nan(j, "insertion_mm");
    r.runtime_s = number_or_nan(j, "runtime_s");
    r.max_energy_balance_error = number_or_nan(j, "max_energy_balance_error");
    r.max_penetration_mm = number_or_nan(j, "max_penetration_mm");
    r.particles_inside = j.value("particles_inside", -1L);
    r.label = j.value("label", std::string());
    r.end_forces_N = j.at("end_forces_N").get<std::map<std::string, double>>();
    r.run_folder = j.at("run_folder").get<std::string>();
    return r;
  } catch (const json::exception& e) {
    throw InputError(fmt::format("{}: not a case record of a study ({})", source, json_error_words(e)));
  }
}

fs::path case_folder(const fs::path& study_dir, const std::string& case_name) { return study_dir / "cases" / case_name; }

std::optional<CaseResult> read_done_case(const fs::path& study_dir, const std::string& case_name, const json& values) {
  const fs::path file = case_folder(study_dir, case_name) / "case.json";
  if (!fs::exists(file)) return std::nullopt;
  const CaseResult r = case_result_from_json(read_json_file(file.string(), "case record"), file.string());
  if (!r.done() || r.values != values) return std::nullopt;
  if (!r.run_folder.empty()) {
    const fs::path summary = study_dir / r.run_folder / "summary.json";
    if (!fs::is_regular_file(summary)) return std::nullopt;
    try {
      if (run_outcome(read_json_file(summary.string(), "run summary")).status != r.status) return std::nullopt;
    } catch (const InputError&) {
      return std::nullopt;  // a summary cut short or not a run's: the case runs again
    }
  }
  return r;
}

void write_case_record(const fs::path& study_dir, const CaseResult& r) {
  const fs::path dir = case_folder(study_dir, r.name);
  fs::create_directories(dir);
  write_file_atomically((dir / "case.json").string(), [&](const std::string& scratch) {
    std::ofstream out(scratch);
    out << case_result_to_json(r).dump(2) << "\n";
    NEEDLE_REQUIRE(out.good(), "cannot write " + scratch);
  });
}

CaseResult run_design_case(const DesignBase& base, int index, const std::string& case_name, const json& values, const fs::path& study_dir,
                           int threads, bool quiet, const std::string& label) {
  CaseResult r = case_record(index, case_name, label, values, "pending", "");
  const fs::path dir = case_folder(study_dir, case_name);
  fs::create_directories(dir);
  const auto start = std::chrono::steady_clock::now();
  const auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  try {
    CaseSetup setup = case_setup(base, values);
    r.reason = tip_infeasibility(setup);
    if (!r.reason.empty()) {
      r.status = "infeasible";
      write_case_record(study_dir, r);
      return r;
    }
    if (setup.recipe) {
      const fs::path recipe_file = dir / "recipe.json";
      write_file_atomically(recipe_file.string(), [&](const std::string& scratch) { std::ofstream(scratch) << recipe_to_json(*setup.recipe).dump(2) << "\n"; });
      setup.scene.needle.select_source("", std::nan(""), recipe_file.string());
    }
    RunOptions run;
    run.out_dir = (dir / "run").string();
    run.overwrite = true;  // a run folder of another scene left by an older plan (the folder's marker is checked)
    run.quiet = quiet;
    run.throw_on_stop = false;
    run.threads = threads;
    run.note = fmt::format("study case {}: {}", case_name, describe_values(values));
    run_insertion_unless_done(setup.scene, run);
  } catch (const InputError& e) {
    r.status = "failed";
    r.reason = e.what();
    r.runtime_s = seconds();
    write_case_record(study_dir, r);
    return r;
  }
  r.run_folder = fs::path("cases") / case_name / "run";
  const RunOutcome o = run_outcome(read_json_file((dir / "run" / "summary.json").string(), "run summary"));
  r.status = o.status;
  r.reason = o.reason;
  r.deflection_mm = o.deflection_mm;
  r.insertion_mm = o.insertion_mm;
  r.runtime_s = o.runtime_s;
  r.max_energy_balance_error = o.max_energy_balance_error;
  r.max_penetration_mm = o.max_penetration_mm;
  r.particles_inside = o.particles_inside;
  r.groove_fill = o.groove_fill;
  r.sample_I_s_mm = o.sample_I_s_mm;
  const fs::path forces_file = dir / "run" / "facet_forces.csv";
  if (fs::exists(forces_file)) {
    const CsvTable forces = read_csv_table(forces_file.string());
    if (!forces.rows.empty()) {
      for (size_t c = 0; c < forces.columns.size(); ++c) {
        const std::string& column = forces.columns[c];
        for (const char* suffix : {"_fx_N", "_fy_N", "_normal_N", "_friction_N"}) {
          const std::string s(suffix);
          if (column.size() > s.size() && column.compare(column.size() - s.size(), s.size(), s) == 0) r.end_forces_N[column] = forces.rows.back()[c];
        }
      }
    }
  }
  if (r.status != "finished" && r.status != "stopped") r.status = "failed";
  write_case_record(study_dir, r);
  return r;
}

std::string describe_values(const json& values) {
  std::string text;
  for (const auto& item : values.items())
    text += fmt::format("{}{}={}", text.empty() ? "" : " ", item.key(),
                        item.value().is_number() ? fmt::format("{:g}", item.value().get<double>()) : setting_text(item.value()));
  return text;
}

}  // namespace needle

namespace needle {
std::string describe_case(const std::string& label, const nlohmann::json& values) {
  return label.empty() ? describe_values(values) : label;
}
}  // namespace needle
