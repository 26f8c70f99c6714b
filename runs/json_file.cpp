#include "runs/json_file.h"

#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <set>
#include <vector>

#include "core/input_error.h"
#include "core/input_file.h"

namespace needle {

nlohmann::json read_json_file(const std::string& path, const std::string& what) {
  check_input_file(path, what);
  std::ifstream in(path);
  NEEDLE_REQUIRE(in.good(), fmt::format("cannot read the {} '{}'", what, path));
  try {
    return parse_json_refusing_duplicates(in, path);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: not valid JSON ({})", path, json_error_words(e)));
  }
}

nlohmann::json parse_json_refusing_duplicates(std::istream& in, const std::string& path) {
  using json = nlohmann::json;
  std::vector<std::set<std::string>> keys;  // per open object, the keys seen so far
  std::vector<std::string> names;           // the open objects' keys, for the message
  std::string last_key;
  const json::parser_callback_t check = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:  // an array has no keys; its objects open their own sets
        keys.emplace_back();
        names.push_back(last_key);
        last_key.clear();
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        keys.pop_back();
        names.pop_back();
        last_key.clear();
        break;
      case json::parse_event_t::key: {
        last_key = parsed.get<std::string>();
        if (!keys.back().insert(last_key).second) {
          std::string name;
          for (const std::string& part : names)
            if (!part.empty()) name += part + ".";
          throw InputError(fmt::format("{}: duplicate key '{}{}' (a key may be given once in its object)", path, name, last_key));
        }
        break;
      }
      default:
        break;
    }
    return true;
  };
  return json::parse(in, check);
}

std::string json_error_words(const std::exception& e) {
  const std::string what = e.what();
  if (what.rfind("[json.exception.", 0) == 0) {
    const size_t end = what.find("] ");
    if (end != std::string::npos) return what.substr(end + 2);
  }
  return what;
}

double number_or_nan(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace needle
