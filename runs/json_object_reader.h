#pragma once
// Reads a JSON object's keys one by one with explicit defaults; finish() reports any key left unread
// (misspelt, or without its unit suffix) as an InputError naming the file and the key.
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "core/input_error.h"

namespace needle {

// Reads an object's keys through this, so that anything left unread is reported as unknown.
class ObjectReader {
 public:
  ObjectReader(const nlohmann::json& object, std::string where, std::string source)
      : object_(object), where_(std::move(where)), source_(std::move(source)) {
    NEEDLE_REQUIRE(object.is_object(), fmt::format("{}: '{}' must be a JSON object", source_, where_));
  }
  bool has(const std::string& key) const { return object_.contains(key); }
  double number(const std::string& key, double fallback) {
    used_.insert(key);
    if (!object_.contains(key)) return fallback;
    const nlohmann::json& v = object_.at(key);
    NEEDLE_REQUIRE(v.is_number(), fmt::format("{}: '{}.{}' must be a number", source_, where_, key));
    return v.get<double>();
  }
  std::string text(const std::string& key, const std::string& fallback) {
    used_.insert(key);
    if (!object_.contains(key)) return fallback;
    const nlohmann::json& v = object_.at(key);
    NEEDLE_REQUIRE(v.is_string(), fmt::format("{}: '{}.{}' must be a string", source_, where_, key));
    return v.get<std::string>();
  }
  bool boolean(const std::string& key, bool fallback) {
    used_.insert(key);
    if (!object_.contains(key)) return fallback;
    const nlohmann::json& v = object_.at(key);
    NEEDLE_REQUIRE(v.is_boolean(), fmt::format("{}: '{}.{}' must be true or false", source_, where_, key));
    return v.get<bool>();
  }
  const nlohmann::json& child(const std::string& key) {
    used_.insert(key);
    return object_.at(key);
  }
  void finish() const {
    for (const auto& item : object_.items())
      NEEDLE_REQUIRE(used_.count(item.key()),
                     fmt::format("{}: unknown key '{}.{}' (misspelt, or without its unit suffix?)", source_,
                                 where_, item.key()));
  }

 private:
  const nlohmann::json& object_;
  std::string where_, source_;
  std::set<std::string> used_;
};

}  // namespace needle
