#pragma once
// A whole JSON file read at once (summaries, reference tables, calibrations): one InputError for a
// file that cannot be read ("cannot read the <what> '<path>'") or is not JSON.
#include <istream>
#include <nlohmann/json.hpp>
#include <string>

namespace needle {

nlohmann::json read_json_file(const std::string& path, const std::string& what);

// JSON text parsed with a key given twice in one object refused (nlohmann keeps the last one without a word):
// InputError "<path>: duplicate key 'a.b' ..." (what names the file in messages). Other parse errors are
// nlohmann's exceptions, for the caller to word.
nlohmann::json parse_json_refusing_duplicates(std::istream& in, const std::string& path);

// A parse error of nlohmann's in the project's words: its message without the "[json.exception.parse_error.101] "
// tag (e.g. "number overflow parsing '1e999'").
std::string json_error_words(const std::exception& e);

// j[key] when it is a number, NaN otherwise (a missing or null field).
double number_or_nan(const nlohmann::json& j, const char* key);

}  // namespace needle
