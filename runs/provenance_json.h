#pragma once
// core/provenance.h as the `provenance` entry of the files results are stored in (summary.json, sweep.json, the paper
// report's results.json, calibration.json): {"version", "commit", "uncommitted_changes", "build_type", "blas", "lapack"}.
#include <nlohmann/json.hpp>

namespace needle {

nlohmann::json provenance_json();

}  // namespace needle
