#pragma once
// Reads one object of a line-tracked JSON document key by key (internal to the scene reader):
// numbers with range checks, quantities with units, and finish() to refuse keys nobody read.
// Every message starts with "file:line:" and names the full key ("motion.travel_mm").
#include <Eigen/Dense>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "core/units.h"
#include "runs/json_lines.h"

namespace needle {

// Checks a value (internal units); returns an empty string if fine, else what is wrong.
using ValueCheck = std::function<std::string(double)>;
ValueCheck positive();
ValueCheck non_negative();
ValueCheck within(double low, double high);  // closed interval
ValueCheck any_finite();

class SceneObject {
 public:
  SceneObject(const JsonDocument& doc, std::string pointer, std::string name);

  bool has(const std::string& key) const;
  double number(const std::string& key, double fallback, const ValueCheck& check);
  int integer(const std::string& key, int fallback, int low, int high);
  bool boolean(const std::string& key, bool fallback);
  std::string text(const std::string& key, const std::string& fallback);
  // A dimensional value: "<base><suffix>": number in the suffix's unit, or "<base>": "<number> <unit>".
  // Returns internal units (mm, ms, mm/ms, MPa, g/mm^3, deg).
  double quantity(const std::string& base, Dimension dimension, double fallback, const ValueCheck& check);
  Eigen::Vector3d vector3(const std::string& key, const Eigen::Vector3d& fallback);
  // A non-empty array of numbers, each passing check.
  std::vector<double> numbers(const std::string& key, const std::vector<double>& fallback, const ValueCheck& check);
  SceneObject child(const std::string& key);
  const nlohmann::json& raw(const std::string& key);  // marks the key read
  std::string where(const std::string& key) const;   // "file:line: name.key"
  void finish() const;

 private:
  const JsonDocument& doc_;
  const nlohmann::json& object_;
  std::string pointer_, name_;
  std::set<std::string> used_;
};

}  // namespace needle
