#pragma once
// One line that says which model a run folder's scene.json ran (`needle paper`'s report and results.json "tissue"):
// the particles and the needle's cut always; the tissue law, relaxation, block, slit, crack, contact, cutting
// pressure, entry face, drive and groove start only where they are not the paper's model or the defaults.
#include <nlohmann/json.hpp>
#include <string>

namespace needle {

// `particles`: the run's particle count (its summary.json). Empty for a scene without a tissue.
std::string describe_run_model(const nlohmann::json& scene, long particles);

}  // namespace needle
