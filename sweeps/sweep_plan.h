#pragma once
// A sweep file (docs/sweeps.md) and the cases it makes: the base scene, the design variables as lists or ranges
// (a full grid over them), ranges sampled by a seeded Latin hypercube, or a list of explicit cases (each its own
// variables and a label: the hard-case suite). Everything a bad file can get wrong is
// found here, before any case runs: unknown keys and variables, empty ranges, values the scene refuses, a sweep
// whose every tip is infeasible.
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sweeps/design_case.h"

namespace needle {

struct SweepCase {
  int index = 0;
  std::string name;   // case_0007
  std::string label;  // what the case is for (explicit cases may say), or empty
  nlohmann::json values = nlohmann::json::object();  // variable -> value (an explicit case sets only its own)
};

struct SweepPlan {
  std::string source;                  // the sweep file
  DesignBase base;
  std::vector<std::string> variables;  // the table's variable columns (alphabetical)
  std::string design;                  // "grid", "latin hypercube, N samples, seed S" or "cases"
  std::vector<SweepCase> cases;
};

// InputError naming the file, line and key for anything wrong.
SweepPlan read_sweep_file(const std::string& path);

// The plan as stored in the sweep's folder (sweep_plan.json): base, design and cases.
nlohmann::json sweep_plan_to_json(const SweepPlan& plan);

// Sets up every case's scene and tip before anything runs: InputError naming the case for a value the scene refuses,
// or when no case's tip can be ground. Returns the infeasible cases' reasons (index -> reason).
std::map<int, std::string> check_sweep_cases(const SweepPlan& plan);

// The file in a study's folder that names the code (core/provenance.h) that began it.
inline constexpr const char* kStudyCodeFile = "study_code.txt";
// Whether `plan` is `stored` with more cases after its own, everything else the same: a listed design that grew (a
// study's partial batch completed). The stored cases keep their names and values, so their records stay done.
bool plan_extends(const nlohmann::json& plan, const nlohmann::json& stored);
// The study folder for this plan: created with its plan file (stored_name, e.g. sweep_plan.json), or an existing
// one whose plan file is the same study, or one this plan extends (plan_extends; the plan file is then rewritten),
// (cases may be done already) and whose cases this code began (its kStudyCodeFile; a folder from before has none and
// takes this code's). InputError otherwise, nothing changed: another study, or another code unless allow_other_code
// (--allow-other-code).
void claim_study_folder(const std::filesystem::path& dir, const std::string& stored_name, const nlohmann::json& plan,
                        bool allow_other_code = false);

}  // namespace needle
