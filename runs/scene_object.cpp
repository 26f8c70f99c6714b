#include "runs/scene_object.h"

#include <cmath>
#include <fmt/format.h>
#include <sstream>
#include <vector>

#include "core/input_error.h"
#include "core/units.h"

namespace needle {

ValueCheck positive() {
  return [](double v) { return v > 0 ? "" : "must be positive"; };
}
ValueCheck non_negative() {
  return [](double v) { return v >= 0 ? "" : "must not be negative"; };
}
ValueCheck within(double low, double high) {
  return [=](double v) { return v >= low && v <= high ? std::string() : fmt::format("must lie in [{}, {}]", low, high); };
}
ValueCheck any_finite() {
  return [](double) { return ""; };
}


SceneObject::SceneObject(const JsonDocument& doc, std::string pointer, std::string name)
    : doc_(doc), object_(pointer.empty() ? doc.value : doc.value.at(nlohmann::json::json_pointer(pointer))),
      pointer_(std::move(pointer)), name_(std::move(name)) {
  NEEDLE_REQUIRE(object_.is_object(), fmt::format("{}: '{}' must be a JSON object {{...}}", doc_.where(pointer_),
                                                  name_.empty() ? "the scene" : name_));
}

std::string SceneObject::where(const std::string& key) const {
  return fmt::format("{}: {}{}", doc_.where(pointer_ + "/" + json_pointer_token(key)), name_.empty() ? "" : name_ + ".", key);
}

bool SceneObject::has(const std::string& key) const { return object_.contains(key); }

const nlohmann::json& SceneObject::raw(const std::string& key) {
  used_.insert(key);
  return object_.at(key);
}

double SceneObject::number(const std::string& key, double fallback, const ValueCheck& check) {
  used_.insert(key);
  if (!has(key)) return fallback;
  const nlohmann::json& v = object_.at(key);
  NEEDLE_REQUIRE(v.is_number(), fmt::format("{} must be a number", where(key)));
  const double value = v.get<double>();
  const std::string problem = std::isfinite(value) ? check(value) : "must be finite";
  NEEDLE_REQUIRE(problem.empty(), fmt::format("{} {} (got {})", where(key), problem, value));
  return value;
}

int SceneObject::integer(const std::string& key, int fallback, int low, int high) {
  used_.insert(key);
  if (!has(key)) return fallback;
  const nlohmann::json& v = object_.at(key);
  NEEDLE_REQUIRE(v.is_number_integer(), fmt::format("{} must be a whole number", where(key)));
  const long long value = v.get<long long>();
  NEEDLE_REQUIRE(value >= low && value <= high, fmt::format("{} must lie in [{}, {}] (got {})", where(key), low, high, value));
  return static_cast<int>(value);
}

bool SceneObject::boolean(const std::string& key, bool fallback) {
  used_.insert(key);
  if (!has(key)) return fallback;
  NEEDLE_REQUIRE(object_.at(key).is_boolean(), fmt::format("{} must be true or false", where(key)));
  return object_.at(key).get<bool>();
}

std::string SceneObject::text(const std::string& key, const std::string& fallback) {
  used_.insert(key);
  if (!has(key)) return fallback;
  NEEDLE_REQUIRE(object_.at(key).is_string(), fmt::format("{} must be a string", where(key)));
  return object_.at(key).get<std::string>();
}

double SceneObject::quantity(const std::string& base, Dimension dimension, double fallback, const ValueCheck& check) {
  const std::string suffixed = base + canonical_suffix(dimension);
  used_.insert(base);
  NEEDLE_REQUIRE(!(has(base) && has(suffixed)), fmt::format("{}: give '{}' or '{}', not both", where(base), base, suffixed));
  if (has(suffixed)) {
    const double canonical = number(suffixed, 0.0, any_finite()) * canonical_to_internal(dimension);
    const std::string problem = check(canonical);
    NEEDLE_REQUIRE(problem.empty(), fmt::format("{} {} (got {})", where(suffixed), problem, object_.at(suffixed).get<double>()));
    return canonical;
  }
  used_.insert(suffixed);
  if (!has(base)) return fallback;
  const nlohmann::json& v = object_.at(base);
  NEEDLE_REQUIRE(v.is_string(), fmt::format("{} is {} and needs a unit: write \"{} <unit>\" or use '{}'", where(base),
                                            dimension_name(dimension), v.dump(), suffixed));
  std::istringstream in(v.get<std::string>());
  double magnitude = 0;
  std::string unit, rest;
  in >> magnitude;
  NEEDLE_REQUIRE(!in.fail(), fmt::format("{}: '{}' does not start with a number", where(base), v.get<std::string>()));
  in >> unit >> rest;
  NEEDLE_REQUIRE(!unit.empty() && rest.empty(), fmt::format("{}: write a number and one unit, like \"3 mm\" (got '{}')", where(base),
                                                            v.get<std::string>()));
  if (const UnitSpec* u = find_unit(unit)) {
    NEEDLE_REQUIRE(u->dimension == dimension, fmt::format("{}: '{}' is not {}", where(base), unit, dimension_name(dimension)));
    const double value = magnitude * u->to_internal;
    const std::string problem = std::isfinite(value) ? check(value) : "must be finite";
    NEEDLE_REQUIRE(problem.empty(), fmt::format("{} {} (got {})", where(base), problem, v.get<std::string>()));
    return value;
  }
  throw InputError(fmt::format("{}: unknown unit '{}'; {} is expected", where(base), unit, dimension_name(dimension)));
}

Eigen::Vector3d SceneObject::vector3(const std::string& key, const Eigen::Vector3d& fallback) {
  used_.insert(key);
  if (!has(key)) return fallback;
  const nlohmann::json& v = object_.at(key);
  NEEDLE_REQUIRE(v.is_array() && v.size() == 3 && v[0].is_number() && v[1].is_number() && v[2].is_number(),
                 fmt::format("{} must be three numbers [x, y, z]", where(key)));
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

std::vector<double> SceneObject::numbers(const std::string& key, const std::vector<double>& fallback, const ValueCheck& check) {
  used_.insert(key);
  if (!has(key)) return fallback;
  const nlohmann::json& v = object_.at(key);
  NEEDLE_REQUIRE(v.is_array() && !v.empty(), fmt::format("{} must be a non-empty array of numbers", where(key)));
  std::vector<double> out;
  for (const auto& e : v) {
    NEEDLE_REQUIRE(e.is_number(), fmt::format("{} must be a non-empty array of numbers", where(key)));
    const double x = e.get<double>();
    const std::string problem = check(x);
    NEEDLE_REQUIRE(problem.empty(), fmt::format("{} {} (got {})", where(key), problem, x));
    out.push_back(x);
  }
  return out;
}

SceneObject SceneObject::child(const std::string& key) {
  used_.insert(key);
  return SceneObject(doc_, pointer_ + "/" + json_pointer_token(key), name_.empty() ? key : name_ + "." + key);
}

void SceneObject::finish() const {
  for (const auto& item : object_.items())
    NEEDLE_REQUIRE(used_.count(item.key()), fmt::format("{}: unknown key (misspelt, or without its unit suffix?)", where(item.key())));
}

}  // namespace needle
