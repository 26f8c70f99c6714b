#pragma once
// A numeric CSV table with a header line (the run folders' history.csv and facet_forces.csv).
#include <string>
#include <vector>

namespace needle {

struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  // The column's index; InputError naming the file if it is missing.
  size_t index(const std::string& column) const;
  bool has(const std::string& column) const;
  std::vector<double> column(const std::string& name) const;
  std::string source;
};

// InputError for a missing file, an empty one or a row whose field count differs from the header's.
// Fields that are not numbers read as NaN.
CsvTable read_csv_table(const std::string& path);

}  // namespace needle
