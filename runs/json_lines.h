#pragma once
// JSON read with the line of every key, so that errors in hand-written input files (scenes) can say
// "scene.json:12: ...". nlohmann::json keeps no positions; the file is parsed through its SAX
// interface with an input iterator that counts newlines as the parser consumes them.
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace needle {

struct JsonDocument {
  std::string source;                // file name, for messages
  nlohmann::json value;
  std::map<std::string, int> lines;  // JSON pointer of each key ("/motion/travel_mm") -> 1-based line

  // "source:line" for a pointer, or just "source" when its line is unknown.
  std::string where(const std::string& pointer) const;
};

// A key as one token of a JSON pointer ("~" -> "~0", "/" -> "~1").
std::string json_pointer_token(const std::string& key);

// InputError naming the file and line on unreadable files or invalid JSON.
JsonDocument parse_json_with_lines(const std::string& text, const std::string& source);
JsonDocument read_json_with_lines(const std::string& path);

}  // namespace needle
