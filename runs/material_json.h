#pragma once
// The tissue card as JSON (data/materials/): keys named with their units, unknown keys are errors.
//   {"E_MPa": 0.665, "nu": 0.45, "density_g_per_cm3": 0.98, "k_MPa": 0.35, "n": 2.75,
//    "rate_law": "plausible" | "printed" | "off", "rate_C_per_ms": 0.1, "rate_p": 0.1, "max_rate_factor": 1000}
#include <nlohmann/json.hpp>
#include <string>

#include "solver/tissue/tissue_material.h"

namespace needle {

// Keys absent from the object keep the values of `defaults`.
TissueMaterial material_from_json(const nlohmann::json& json, const std::string& source, const TissueMaterial& defaults = {});
TissueMaterial read_material_file(const std::string& path);
nlohmann::json material_to_json(const TissueMaterial& material);

}  // namespace needle
