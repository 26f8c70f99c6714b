#pragma once
// One case of a design study (a sweep or an optimisation): the base scene of the study with the case's design
// variables set, run as the whole pipeline (CAD -> mesh -> particles -> insertion) into its own folder, and the
// case's record (case.json: variables, status, reason, deflection, groove fill, the facet forces at the end,
// runtime) that the study's table is built from. docs/sweeps.md describes the files and the variables.
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "geometry/grinding_recipe.h"
#include "runs/json_lines.h"
#include "runs/scene.h"

namespace needle {

// The scene every case starts from: a scene file or the run defaults of `needle run` (the paper scene, E from the
// shipped SB calibration), a needle over it, a model level and fixed scene keys.
struct DesignBase {
  std::string scene_file;        // absolute; empty: the run defaults
  std::string preset, recipe_file;  // the needle over the scene's (at most one of preset, recipe, d_a)
  double d_a_mm = std::nan("");
  std::string calibration_file;  // E from this calibration (`needle calibrate`); empty: the scene's, or the shipped one without a scene
  std::string model;             // the model level (runs/model_levels.h); empty: the scene's
  nlohmann::json settings = nlohmann::json::object();  // "set": dotted scene key -> value
};

// InputError at the key's line for a key of the object (at JSON pointer `pointer`) that is not one of `known`:
// "<file>:<line>: unknown key '<key>' (known: a, b, c)".
void refuse_unknown_keys(const JsonDocument& doc, const nlohmann::json& object, const std::string& pointer, const std::vector<std::string>& known);

// Reads the study file's "base", "model" and "set" entries (the keys it does not know are the caller's); paths are
// taken relative to the study file's folder. InputError naming the file and line.
DesignBase read_design_base(const JsonDocument& doc);
nlohmann::json design_base_to_json(const DesignBase& base);

// The tip's design variables (the multi-bevel family of docs/geometry.md). Every other variable is a dotted scene key
// (tissue.friction, motion.speed_mm_per_ms, needle.groove_start_mm, ...).
const std::vector<std::string>& tip_variable_names();
bool is_tip_variable(const std::string& name);
// InputError (with `where`) unless the name is a tip variable or a dotted scene key.
void check_variable_name(const std::string& name, const std::string& where);

// The case's scene and, where its tip variables call for one, its grinding recipe (a multi-bevel tip whose angles
// differ from the paper's). InputError for a value the scene refuses.
struct CaseSetup {
  Scene scene;
  std::optional<GrindingRecipe> recipe;
};
CaseSetup case_setup(const DesignBase& base, const nlohmann::json& values);

// The recipe the case's needle is ground by (none for a mesh file or a plain rod), its groove start applied.
std::optional<GrindingRecipe> case_recipe(const CaseSetup& setup);

// A case's tip is feasible when the grinding model can make it; the reason otherwise (empty when feasible).
std::string tip_infeasibility(const CaseSetup& setup);

// A case's outcome. Status: finished, stopped (the solver stopped, with its reason: the monitor that fired),
// infeasible (the tip cannot be ground), timed_out (stopped at the sweep's time limit for a case), failed (anything
// else, e.g. a worker that died), pending (not run yet).
struct CaseResult {
  int index = -1;
  std::string name, label;
  nlohmann::json values = nlohmann::json::object();
  std::string status = "pending", reason;
  double deflection_mm = std::nan(""), groove_fill = std::nan(""), insertion_mm = std::nan(""), runtime_s = std::nan("");
  double max_energy_balance_error = std::nan(""), max_penetration_mm = std::nan("");  // the run's worst
  double sample_I_s_mm = std::nan("");  // the sample's length when the scene fires the cannula (NaN: it does not)
  long particles_inside = -1;                                                          // at the end (-1: not run)
  std::map<std::string, double> end_forces_N;  // facet_forces.csv's last row: each facet's fx, fy, normal and friction
  std::string run_folder;                     // relative to the study folder

  bool done() const { return status == "finished" || status == "stopped" || status == "infeasible" || status == "timed_out"; }
};
nlohmann::json case_result_to_json(const CaseResult& result);
// A finished case's responses in words for the progress lines: "deflection +0.1234 mm, groove fill 0.987[, I_s 12.3 mm]".
std::string finished_case_words(const CaseResult& result);
// The record of a case that ended without a run's result (timed out, failed, infeasible), with its reason.
CaseResult case_record(int index, const std::string& name, const std::string& label, const nlohmann::json& values, const std::string& status,
                       const std::string& reason);
CaseResult case_result_from_json(const nlohmann::json& json, const std::string& source);

// The case's folder inside a study folder: DIR/cases/<name>.
std::filesystem::path case_folder(const std::filesystem::path& study_dir, const std::string& case_name);
// The case's record if DIR/cases/<name>/case.json holds a done case of these variables and, for a case that ran, its
// run folder still holds the run it records (its summary.json with the same status): a record whose run was lost or
// replaced is not done, and the case runs again.
std::optional<CaseResult> read_done_case(const std::filesystem::path& study_dir, const std::string& case_name, const nlohmann::json& values);

// Runs the case into DIR/cases/<name>/run (reusing a finished run of the same scene there) and writes case.json
// atomically. A stopped or infeasible case is a result, not an error; Interrupted (Ctrl-C) propagates with no
// case.json written, so that the case runs again next time.
CaseResult run_design_case(const DesignBase& base, int index, const std::string& case_name, const nlohmann::json& values,
                           const std::filesystem::path& study_dir, int threads, bool quiet, const std::string& label = "");
// Writes a case's record (case.json) atomically: also used for a case whose worker died.
void write_case_record(const std::filesystem::path& study_dir, const CaseResult& result);

// "d_a_mm=-0.1 tissue.friction=0.2"
std::string describe_values(const nlohmann::json& values);
// The case's label where it has one, else its values.
std::string describe_case(const std::string& label, const nlohmann::json& values);

}  // namespace needle
