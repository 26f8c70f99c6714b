#include "runs/csv_table.h"

#include <algorithm>
#include <cstdlib>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/input_error.h"
#include "core/input_file.h"

namespace needle {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

}  // namespace

size_t CsvTable::index(const std::string& name) const {
  const auto it = std::find(columns.begin(), columns.end(), name);
  NEEDLE_REQUIRE(it != columns.end(), fmt::format("{}: no column '{}'", source, name));
  return static_cast<size_t>(it - columns.begin());
}

bool CsvTable::has(const std::string& name) const { return std::find(columns.begin(), columns.end(), name) != columns.end(); }

std::vector<double> CsvTable::column(const std::string& name) const {
  const size_t k = index(name);
  std::vector<double> out;
  out.reserve(rows.size());
  for (const auto& row : rows) out.push_back(row[k]);
  return out;
}

CsvTable read_csv_table(const std::string& path) {
  check_input_file(path, "table");
  std::ifstream in(path);
  NEEDLE_REQUIRE(in.good(), fmt::format("cannot read '{}'", path));
  CsvTable table;
  table.source = path;
  std::string line;
  NEEDLE_REQUIRE(static_cast<bool>(std::getline(in, line)), fmt::format("{}: empty file", path));
  table.columns = split(line);
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    const std::vector<std::string> fields = split(line);
    NEEDLE_REQUIRE(fields.size() == table.columns.size(),
                   fmt::format("{}:{}: {} fields where the header has {}", path, line_number, fields.size(), table.columns.size()));
    std::vector<double> row;
    row.reserve(fields.size());
    for (const std::string& f : fields) {
      char* end = nullptr;
      const double v = std::strtod(f.c_str(), &end);
      row.push_back(end != f.c_str() && *end == '\0' ? v : std::numeric_limits<double>::quiet_NaN());
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

}  // namespace needle
