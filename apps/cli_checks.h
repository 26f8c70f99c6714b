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

}  // namespace needle
