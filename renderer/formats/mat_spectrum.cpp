#include "renderer/formats/mat_spectrum.h"

#include <cmath>

#include "renderer/core/errors/error.h"
#include "renderer/formats/mat_file.h"

namespace ofl {
namespace {

std::string variable_list(const MatVariables& vars) {
  std::string s;
  for (auto& v : vars) s += (s.empty() ? "" : ", ") + v.first;
  return s.empty() ? "none" : s;
}

const MatValue* find_variable(const MatVariables& vars, const std::string& name) {
  for (auto& v : vars)
    if (v.first == name) return &v.second;
  return nullptr;
}

std::vector<std::string> column_names(const std::string& file, const MatVariables& vars, size_t k) {
  std::vector<std::string> names;
  if (const MatValue* fn = find_variable(vars, "filterNames")) {
    if (fn->kind != MatValue::Kind::kCell || fn->cells.size() != k)
      throw InputError(file, "variable \"filterNames\"", "expected a cell of " + std::to_string(k) + " names (one per column of data)");
    for (size_t i = 0; i < k; ++i) {
      if (fn->cells[i].kind != MatValue::Kind::kText || fn->cells[i].text.empty())
        throw InputError(file, "variable \"filterNames\"", "entry " + std::to_string(i + 1) + " is not a name");
      // ISETCam pads names in some files (' led525' in SixLEDs.mat): columns match without the spaces.
      std::string n = fn->cells[i].text;
      size_t a = n.find_first_not_of(" \t"), b = n.find_last_not_of(" \t");
      if (a == std::string::npos) throw InputError(file, "variable \"filterNames\"", "entry " + std::to_string(i + 1) + " is blank");
      names.push_back(n.substr(a, b - a + 1));
    }
    return names;
  }
  if (k == 1) return {"data"};
  for (size_t i = 0; i < k; ++i) names.push_back(std::to_string(i + 1));
  return names;
}

}  // namespace

CsvNumeric read_spectrum_mat(const std::filesystem::path& path) {
  const std::string file = path.string();
  MatVariables vars = read_mat_file(path);
  const char* wname = "wavelength";
  const MatValue* w = find_variable(vars, wname);
  if (!w) { wname = "wave"; w = find_variable(vars, wname); }
  if (!w)
    throw InputError(file, "variable \"wavelength\"",
                     "missing: an ISETCam spectral file holds the variables wavelength and data (this file has: " +
                         variable_list(vars) + ")");
  const MatValue* d = find_variable(vars, "data");
  if (!d)
    throw InputError(file, "variable \"data\"",
                     "missing: an ISETCam spectral file holds the variables wavelength and data (this file has: " +
                         variable_list(vars) + ")");
  const std::string wfield = std::string("variable \"") + wname + "\"";
  std::vector<double> nm = mat_numbers(file, *w, wfield);
  if (w->dims.size() != 2 || (w->dims[0] != 1 && w->dims[1] != 1))
    throw InputError(file, wfield, "expected a vector of wavelengths in nm");
  const size_t n = nm.size();
  if (n < 2) throw InputError(file, wfield, "a spectrum needs at least two wavelengths");
  for (size_t i = 1; i < n; ++i)
    if (!(nm[i] > nm[i - 1]))
      throw InputError(file, wfield, "wavelengths must increase (" + std::to_string(nm[i]) + " nm after " +
                                         std::to_string(nm[i - 1]) + " nm)");
  if (d->kind != MatValue::Kind::kNumeric) throw InputError(file, "variable \"data\"", "expected a numeric matrix");
  if (d->dims.size() != 2) throw InputError(file, "variable \"data\"", "expected a matrix (wavelengths x spectra)");
  // data(i, j): wavelength i, spectrum j. A single spectrum stored as a row is accepted too.
  size_t rows = d->dims[0], cols = d->dims[1];
  bool transposed = false;
  if (rows != n) {
    if (cols == n && rows >= 1) {
      transposed = true;
      std::swap(rows, cols);
    } else {
      throw InputError(file, "variable \"data\"", "is " + std::to_string(d->dims[0]) + " x " + std::to_string(d->dims[1]) +
                                                      " but wavelength has " + std::to_string(n) + " values");
    }
  }
  const size_t k = cols;
  if (k == 0) throw InputError(file, "variable \"data\"", "has no columns");
  CsvNumeric t;
  t.file = file;
  t.header.push_back("wavelength_nm");
  for (auto& name : column_names(file, vars, k)) t.header.push_back(name);
  for (size_t i = 0; i < n; ++i) {
    std::vector<double> row = {nm[i]};
    for (size_t j = 0; j < k; ++j)
      row.push_back(transposed ? d->numbers[i * d->dims[0] + j] : d->numbers[j * n + i]);
    t.rows.push_back(std::move(row));
    t.lines.push_back(int(i + 1));
  }
  return t;
}

void write_spectrum_mat(const std::filesystem::path& file, const std::vector<double>& nm,
                        const std::vector<std::vector<double>>& columns, const std::vector<std::string>& names,
                        const std::string& comment) {
  const size_t n = nm.size(), k = columns.size();
  std::vector<double> data;
  data.reserve(n * k);
  for (auto& c : columns) {
    if (c.size() != n) throw std::logic_error("write_spectrum_mat: a column's length differs from the wavelengths'");
    data.insert(data.end(), c.begin(), c.end());
  }
  MatVariables vars;
  vars.emplace_back("wavelength", MatValue::vector(nm, true));
  vars.emplace_back("data", MatValue::array({n, k}, std::move(data)));
  if (!names.empty()) {
    std::vector<MatValue> cells;
    for (auto& s : names) cells.push_back(MatValue::string(s));
    vars.emplace_back("filterNames", MatValue::cell_row(std::move(cells)));
  }
  vars.emplace_back("comment", MatValue::string(comment));
  write_mat_file(file, vars);
}

}  // namespace ofl
