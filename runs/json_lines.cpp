#include "runs/json_lines.h"

#include <algorithm>

#include <fmt/format.h>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include "core/input_error.h"
#include "core/input_file.h"
#include "runs/json_file.h"

namespace needle {
namespace {

using nlohmann::json;

// An input iterator over the text that counts the newlines it has passed.
class LineCountingIterator {
 public:
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;
  LineCountingIterator(const char* p, int* line) : p_(p), line_(line) {}
  reference operator*() const { return *p_; }
  LineCountingIterator& operator++() {
    if (*p_ == '\n') ++*line_;
    ++p_;
    return *this;
  }
  LineCountingIterator operator++(int) {
    LineCountingIterator old = *this;
    ++*this;
    return old;
  }
  bool operator==(const LineCountingIterator& o) const { return p_ == o.p_; }
  bool operator!=(const LineCountingIterator& o) const { return p_ != o.p_; }

 private:
  const char* p_;
  int* line_;
};

// Builds the document and records each key's line (the line the parser is on when the key ends).
class LineTrackingBuilder : public nlohmann::json_sax<json> {
 public:
  LineTrackingBuilder(JsonDocument& doc, const int& line) : doc_(doc), line_(line) {}
  bool null() override { return put(nullptr); }
  bool boolean(bool v) override { return put(v); }
  bool number_integer(number_integer_t v) override { return put(v); }
  bool number_unsigned(number_unsigned_t v) override { return put(v); }
  bool number_float(number_float_t v, const string_t&) override { return put(v); }
  bool string(string_t& v) override { return put(v); }
  bool binary(binary_t&) override { return false; }
  bool start_object(std::size_t) override { return open(json::object()); }
  bool start_array(std::size_t) override { return open(json::array()); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }
  bool key(string_t& k) override {
    key_ = k;
    const std::string pointer = pointers_.back() + "/" + json_pointer_token(k);
    const auto earlier = doc_.lines.find(pointer);
    if (earlier != doc_.lines.end() && stack_.back()->contains(k)) {
      std::string name = pointer.substr(1);
      std::replace(name.begin(), name.end(), '/', '.');
      throw InputError(fmt::format("{}:{}: {}: duplicate key (also on line {}; a key may be given once)", doc_.source, line_, name, earlier->second));
    }
    doc_.lines[pointer] = line_;
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) override {
    throw InputError(fmt::format("{}:{}: not valid JSON ({})", doc_.source, line_, json_error_words(e)));
  }

 private:
  // Places a value in the current container; returns where it went and its pointer.
  std::pair<json*, std::string> place(json v) {
    if (stack_.empty()) {
      doc_.value = std::move(v);
      return {&doc_.value, ""};
    }
    json& top = *stack_.back();
    if (top.is_object()) {
      top[key_] = std::move(v);
      return {&top[key_], pointers_.back() + "/" + json_pointer_token(key_)};
    }
    top.push_back(std::move(v));
    return {&top.back(), pointers_.back() + "/" + std::to_string(top.size() - 1)};
  }
  bool put(json v) {
    place(std::move(v));
    return true;
  }
  bool open(json container) {
    // Scenes, recipes and cards nest a few levels; a document nested thousands deep is refused at once (a
    // 50 000-deep one took 18 s to reach the first unknown key, building each level's path).
    constexpr size_t kMaxDepth = 64;
    if (stack_.size() >= kMaxDepth)
      throw InputError(fmt::format("{}:{}: nested deeper than {} levels (scenes and recipes nest a few)", doc_.source, line_, kMaxDepth));
    auto [where, pointer] = place(std::move(container));
    stack_.push_back(where);
    pointers_.push_back(pointer);
    return true;
  }
  bool close() {
    stack_.pop_back();
    pointers_.pop_back();
    return true;
  }

  JsonDocument& doc_;
  const int& line_;
  std::vector<json*> stack_;
  std::vector<std::string> pointers_;
  std::string key_;
};

}  // namespace

std::string json_pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) out += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
  return out;
}

std::string JsonDocument::where(const std::string& pointer) const {
  const auto it = lines.find(pointer);
  return it == lines.end() ? source : fmt::format("{}:{}", source, it->second);
}

JsonDocument parse_json_with_lines(const std::string& text, const std::string& source) {
  JsonDocument doc;
  doc.source = source;
  int line = 1;
  LineTrackingBuilder builder(doc, line);
  const LineCountingIterator first(text.data(), &line), last(text.data() + text.size(), &line);
  json::sax_parse(first, last, &builder);
  return doc;
}

JsonDocument read_json_with_lines(const std::string& path) {
  check_input_file(path, "JSON file");
  std::ifstream in(path, std::ios::binary);
  NEEDLE_REQUIRE(in, fmt::format("cannot read '{}'", path));
  std::stringstream text;
  text << in.rdbuf();
  return parse_json_with_lines(text.str(), path);
}

}  // namespace needle
