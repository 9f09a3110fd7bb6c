// CSV files in the shared-data convention: one header row, comma separated, RFC 4180 quotes,
// "NaN" for missing numbers. read_csv keeps text cells; read_numeric_csv converts every cell and
// reports the file, line and column of anything that is not a number.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace ofl {

struct CsvText {
  std::string file;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;  // 1-based file line of each row
  int column(const std::string& name) const;  // -1 when absent
};

struct CsvNumeric {
  std::string file;
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;  // NaN where the file says NaN
  std::vector<int> lines;
  int column(const std::string& name) const;
  // Index of `name`, or an InputError naming the file and the columns it does have.
  int require_column(const std::string& name) const;
};

CsvText read_csv(const std::filesystem::path& file);
CsvNumeric read_numeric_csv(const std::filesystem::path& file);

std::string csv_quote(const std::string& s);

}  // namespace ofl
