#include "runs/scene_object.h"

#include <cmath>
#include <fmt/format.h>
#include <sstream>
#include <vector>

#include "core/input_error.h"

namespace needle {
namespace {

struct UnitSpec {
  const char* name;
  Dimension dimension;
  double to_internal;
};

// Units a value string may carry; internal units are mm, ms, mm/ms (= m/s), MPa, g/mm^3, deg.
const std::vector<UnitSpec>& units() {
  static const std::vector<UnitSpec> table = {
      {"mm", Dimension::length, 1.0},       {"cm", Dimension::length, 10.0},      {"m", Dimension::length, 1000.0},
      {"um", Dimension::length, 1e-3},      {"ms", Dimension::time, 1.0},         {"s", Dimension::time, 1000.0},
      {"us", Dimension::time, 1e-3},        {"m/s", Dimension::speed, 1.0},       {"mm/ms", Dimension::speed, 1.0},
      {"mm/s", Dimension::speed, 1e-3},     {"MPa", Dimension::stress, 1.0},      {"GPa", Dimension::stress, 1000.0},
      {"kPa", Dimension::stress, 1e-3},     {"Pa", Dimension::stress, 1e-6},      {"g/cm3", Dimension::density, 1e-3},
      {"kg/m3", Dimension::density, 1e-6},  {"g/mm3", Dimension::density, 1.0},   {"deg", Dimension::angle, 1.0},
      {"rad", Dimension::angle, 180.0 / M_PI}};
  return table;
}

const char* dimension_name(Dimension d) {
  switch (d) {
    case Dimension::length: return "a length (mm, cm, m, um)";
    case Dimension::time: return "a time (ms, s, us)";
    case Dimension::speed: return "a speed (m/s, mm/ms, mm/s)";
    case Dimension::stress: return "a stress (MPa, GPa, kPa, Pa)";
    case Dimension::density: return "a density (g/cm3, kg/m3, g/mm3)";
    case Dimension::angle: return "an angle (deg, rad)";
  }
  return "";
}

}  // namespace

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

std::string canonical_suffix(Dimension d) {
  switch (d) {
    case Dimension::length: return "_mm";
    case Dimension::time: return "_ms";
    case Dimension::speed: return "_m_per_s";
    case Dimension::stress: return "_MPa";
    case Dimension::density: return "_g_per_cm3";
    case Dimension::angle: return "_deg";
  }
  return "";
}

double canonical_to_internal(Dimension d) { return d == Dimension::density ? 1e-3 : 1.0; }

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
  for (const UnitSpec& u : units())
    if (u.name == unit) {
      NEEDLE_REQUIRE(u.dimension == dimension, fmt::format("{}: '{}' is not {}", where(base), unit, dimension_name(dimension)));
      const double value = magnitude * u.to_internal;
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
