#include "renderer/core/files/csv.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"

namespace ofl {
namespace {

// Splits one CSV record; handles quoted fields with embedded commas and doubled quotes.
// Quoted fields may not span lines (the shared data never does that).
std::vector<std::string> split_record(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    char c = line[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < line.size() && line[i + 1] == '"') { cur += '"'; ++i; }
        else quoted = false;
      } else {
        cur += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

std::string trim(const std::string& s) {
  size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// Names match without leading and trailing spaces (a scene may quote ISETCam's padded names).
int find_column(const std::vector<std::string>& header, const std::string& name) {
  const std::string want = trim(name);
  for (size_t i = 0; i < header.size(); ++i)
    if (trim(header[i]) == want) return static_cast<int>(i);
  return -1;
}

}  // namespace

int CsvText::column(const std::string& name) const { return find_column(header, name); }
int CsvNumeric::column(const std::string& name) const { return find_column(header, name); }

int CsvNumeric::require_column(const std::string& name) const {
  int c = column(name);
  if (c < 0) {
    std::string have;
    for (auto& h : header) have += (have.empty() ? "" : ", ") + h;
    throw InputError(file, "column \"" + name + "\"", "no such column (columns: " + have + ")");
  }
  return c;
}

CsvText read_csv(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) {
    std::error_code ec;
    throw InputError(file.string(), "", std::filesystem::exists(file, ec) ? "cannot open file" : "file not found");
  }
  CsvText t;
  t.file = file.string();
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (lineno == 1 && line.size() >= 3 && (unsigned char)line[0] == 0xEF) line = line.substr(3);  // BOM
    if (trim(line).empty()) continue;
    auto cells = split_record(line);
    for (auto& c : cells) c = trim(c);
    if (t.header.empty()) {
      t.header = std::move(cells);
      continue;
    }
    if (cells.size() != t.header.size())
      throw InputError(t.file, "line " + std::to_string(lineno),
                       "has " + std::to_string(cells.size()) + " cells, the header has " +
                           std::to_string(t.header.size()));
    t.rows.push_back(std::move(cells));
    t.lines.push_back(lineno);
  }
  if (t.header.empty()) throw InputError(t.file, "", "empty file (no header row)");
  return t;
}

CsvNumeric read_numeric_csv(const std::filesystem::path& file) {
  CsvText t = read_csv(file);
  CsvNumeric n;
  n.file = t.file;
  n.header = t.header;
  n.lines = t.lines;
  n.rows.reserve(t.rows.size());
  for (size_t r = 0; r < t.rows.size(); ++r) {
    std::vector<double> row(t.rows[r].size());
    for (size_t c = 0; c < row.size(); ++c) {
      const std::string& s = t.rows[r][c];
      if (s == "NaN" || s == "nan" || s == "NA" || s.empty()) {
        row[c] = std::nan("");
        continue;
      }
      char* end = nullptr;
      errno = 0;
      double v = std::strtod(s.c_str(), &end);
      if (end == s.c_str() || *end != '\0' || errno == ERANGE)
        throw InputError(n.file, "line " + std::to_string(t.lines[r]) + " column \"" + t.header[c] + "\"",
                         "not a number: \"" + s + "\"");
      row[c] = v;
    }
    n.rows.push_back(std::move(row));
  }
  return n;
}

std::string csv_quote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace ofl
