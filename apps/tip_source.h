#pragma once
// Which tip a command works on: --preset, --d-a (with the multi-bevel angles) or --recipe, plus the
// rod and groove overrides. Shared by `needle tip`, `needle mesh` and later commands.
#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

#include "geometry/grinding_recipe.h"

namespace needle {

struct TipSource {
  std::string preset, recipe_file;
  double d_a_mm = std::nan("");
  MultiBevelAngles angles;
  double rod_length_mm = std::nan(""), groove_start_mm = std::nan(""), chord_tolerance_mm = std::nan("");

  bool given() const { return !preset.empty() || !recipe_file.empty() || !std::isnan(d_a_mm); }
};

void add_tip_source_options(CLI::App& command, TipSource& source);

// The recipe the options describe; InputError unless exactly one of preset, d_a, recipe is given.
GrindingRecipe recipe_from_source(const TipSource& source);

}  // namespace needle
