#include "runs/json_file.h"

#include <limits>

#include <fmt/format.h>
#include <fstream>

#include "core/input_error.h"

namespace needle {

nlohmann::json read_json_file(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  NEEDLE_REQUIRE(in.good(), fmt::format("cannot read the {} '{}'", what, path));
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: not valid JSON ({})", path, e.what()));
  }
}

double number_or_nan(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace needle
