#pragma once
// Checks shared by the commands' flags (CLI11 validators), worded as the project's errors.
#include <CLI/CLI.hpp>
#include <string>

namespace needle {

// A count: a whole number 0 or more (threads, frames).
inline CLI::Validator count_check() {
  return CLI::Validator(
      [](std::string& text) {
        try {
          size_t used = 0;
          const long value = std::stol(text, &used);
          if (used == text.size() && value >= 0) return std::string();
        } catch (const std::exception&) {
        }
        return "must be a whole number 0 or more (got " + text + ")";
      },
      "COUNT");
}

// --allow-other-code, for the commands that run a study's cases into a folder (sweep, optimize, stress): go on with a
// folder whose cases another build began (sweeps/sweep_plan.h: claim_study_folder).
inline void add_allow_other_code_flag(CLI::App* command, bool& allow) {
  command->add_flag("--allow-other-code", allow,
                    "Go on with a study whose cases another build of needle began (its study_code.txt names it): one table then mixes two codes' results");
}

}  // namespace needle
