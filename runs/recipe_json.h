#pragma once
// Grinding recipes as JSON files (see docs/geometry.md and data/presets/): every key is checked,
// unknown or misspelt keys are errors that name the key.
#include <nlohmann/json.hpp>
#include <string>

#include "geometry/grinding_recipe.h"

namespace needle {

GrindingRecipe recipe_from_json(const nlohmann::json& json, const std::string& source);
GrindingRecipe read_recipe_file(const std::string& path);
nlohmann::json recipe_to_json(const GrindingRecipe& recipe);

}  // namespace needle
