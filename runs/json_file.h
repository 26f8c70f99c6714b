#pragma once
// A whole JSON file read at once (summaries, reference tables, calibrations): one InputError for a
// file that cannot be read ("cannot read the <what> '<path>'") or is not JSON.
#include <nlohmann/json.hpp>
#include <string>

namespace needle {

nlohmann::json read_json_file(const std::string& path, const std::string& what);

// j[key] when it is a number, NaN otherwise (a missing or null field).
double number_or_nan(const nlohmann::json& j, const char* key);

}  // namespace needle
