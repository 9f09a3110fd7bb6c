#include "renderer/diagnose/problem/measurement_set.h"

#include <cmath>
#include <cstdlib>
#include <set>

#include "renderer/core/files/csv.h"
#include "renderer/core/errors/error.h"
#include "renderer/spectral/spectra/spectrum.h"

namespace ofl {
namespace fs = std::filesystem;

namespace {

bool parse_number(const std::string& s, double& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end && *end == '\0';
}

fs::path index_of(const fs::path& path, const char* default_name) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path.string(), "", "no such file or folder");
  if (fs::is_directory(path, ec)) {
    fs::path p = path / default_name;
    if (!fs::exists(p, ec)) throw InputError(path.string(), default_name, "the folder has no " + std::string(default_name));
    return p;
  }
  return path;
}

// Tries base/rel, then base/(rel without its first k folders).
fs::path resolve_listed_file(const fs::path& base, const std::string& cell) {
  fs::path rel(cell);
  std::error_code ec;
  if (rel.is_absolute()) return fs::exists(rel, ec) ? rel : fs::path();
  std::vector<fs::path> parts(rel.begin(), rel.end());
  for (size_t k = 0; k < parts.size(); ++k) {
    fs::path p = base;
    for (size_t j = k; j < parts.size(); ++j) p /= parts[j];
    if (fs::is_regular_file(p, ec)) return p;
  }
  return {};
}

bool passes(const CsvText& t, size_t r, const std::vector<RowFilter>& select) {
  for (auto& f : select) {
    int c = t.column(f.column);
    if (c < 0) throw InputError(t.file, "column \"" + f.column + "\"", "selection names a column the table does not have");
    const std::string& cell = c < static_cast<int>(t.rows[r].size()) ? t.rows[r][c] : std::string();
    bool any = false;
    for (auto& v : f.values) any = any || cell_matches(cell, v);
    if (!any) return false;
  }
  return true;
}

std::string cell(const CsvText& t, size_t r, int c) {
  return (c >= 0 && c < static_cast<int>(t.rows[r].size())) ? t.rows[r][c] : std::string();
}

}  // namespace

bool cell_matches(const std::string& cell, const std::string& value) {
  if (cell == value) return true;
  double a, b;
  return parse_number(cell, a) && parse_number(value, b) && a == b;
}

SpectraSet read_spectra_index(const fs::path& path, const std::string& file_column, const std::vector<RowFilter>& select) {
  fs::path index = index_of(path, "index.csv");
  CsvText t = read_csv(index);
  SpectraSet out;
  out.index_file = index.string();
  int fc = t.column(file_column);
  if (fc < 0) throw InputError(t.file, "column \"" + file_column + "\"", "the index has no column naming the spectrum files");
  fs::path base = index.parent_path();
  // Files that other rows list as their duplicate, with those rows' labels: a file claimed by a
  // row of another category/subject/site means one of the two labels is wrong.
  int dup_col = t.column("duplicate_of");
  std::map<std::string, std::vector<size_t>> claimed;
  if (dup_col >= 0)
    for (size_t r = 0; r < t.rows.size(); ++r) {
      std::string d = cell(t, r, dup_col);
      if (!d.empty()) claimed[fs::path(d).stem().string()].push_back(r);
    }
  std::map<std::vector<double>, std::string> seen;  // identical data under two rows
  for (size_t r = 0; r < t.rows.size(); ++r) {
    if (!passes(t, r, select)) continue;
    std::string f = cell(t, r, fc);
    std::string where = "line " + std::to_string(t.lines[r]) + " column " + file_column;
    if (f.empty()) {
      out.notes.push_back("index line " + std::to_string(t.lines[r]) + ": no file (skipped)");
      continue;
    }
    fs::path p = resolve_listed_file(base, f);
    if (p.empty()) throw InputError(t.file, where, "file \"" + f + "\" not found (looked under " + base.string() + ")");
    MeasuredSpectrum m;
    m.file = p.string();
    m.label = p.stem().string();
    m.index_line = t.lines[r];
    for (size_t c = 0; c < t.header.size(); ++c) m.conditions[t.header[c]] = cell(t, r, static_cast<int>(c));
    SpectrumCsvOptions o;
    o.allow_negative = true;  // dark-subtracted radiance scatters around zero; NaN is still an error
    TabulatedSpectrum s = read_spectrum_csv(p, o);
    m.nm = s.nm;
    m.value = s.value;
    auto it = seen.find(m.value);
    if (it != seen.end())
      out.notes.push_back(m.label + " has exactly the same numbers as " + it->second + " (kept both; check the labels)");
    else
      seen[m.value] = m.label;
    auto cl = claimed.find(m.label);
    if (cl != claimed.end())
      for (size_t rr : cl->second) {
        std::string other;
        for (const char* col : {"category", "subject", "site"}) {
          int c = t.column(col);
          if (c >= 0 && cell(t, rr, c) != cell(t, r, c)) other += std::string(other.empty() ? "" : ", ") + col + " " + cell(t, rr, c);
        }
        if (!other.empty())
          out.notes.push_back(m.label + ": index line " + std::to_string(t.lines[rr]) + " (" + other +
                              ") says it holds the same data, so one of the two labels is wrong (kept)");
      }
    out.spectra.push_back(std::move(m));
  }
  if (out.spectra.empty()) throw InputError(t.file, "", "no spectra left after the selection");
  return out;
}

CameraPatchSet read_camera_patches(const fs::path& path, const std::vector<RowFilter>& select) {
  fs::path file = index_of(path, "patches.csv");
  CsvText t = read_csv(file);
  CameraPatchSet out;
  out.file = t.file;
  auto need = [&](const char* name) {
    int c = t.column(name);
    if (c < 0) throw InputError(t.file, std::string("column \"") + name + "\"", "missing (a camera patch table needs patch, r_mean, g_mean, b_mean, radiance_file, radiance_column)");
    return c;
  };
  int c_id = need("patch"), c_rf = need("radiance_file"), c_rc = need("radiance_column");
  int c_mean[3] = {need("r_mean"), need("g_mean"), need("b_mean")};
  int c_sd[3] = {t.column("r_sd"), t.column("g_sd"), t.column("b_sd")};
  int c_n = t.column("n_pixels"), c_exp = t.column("exposure");
  std::map<std::string, CsvNumeric> radiance_files;
  fs::path base = file.parent_path();
  for (size_t r = 0; r < t.rows.size(); ++r) {
    if (!passes(t, r, select)) continue;
    std::string line = "line " + std::to_string(t.lines[r]);
    auto number = [&](int c, const char* name, bool positive) {
      double v;
      std::string s = cell(t, r, c);
      if (!parse_number(s, v) || !std::isfinite(v))
        throw InputError(t.file, line + " column " + name, "\"" + s + "\" is not a finite number");
      if (positive && !(v > 0)) throw InputError(t.file, line + " column " + name, "must be positive");
      return v;
    };
    CameraPatch p;
    p.id = cell(t, r, c_id);
    p.line = t.lines[r];
    const char* names[3] = {"r_mean", "g_mean", "b_mean"};
    const char* sdn[3] = {"r_sd", "g_sd", "b_sd"};
    for (int k = 0; k < 3; ++k) {
      p.rgb[k] = number(c_mean[k], names[k], false);
      if (c_sd[k] >= 0 && !cell(t, r, c_sd[k]).empty()) p.sd[k] = number(c_sd[k], sdn[k], false);
    }
    if (c_n >= 0 && !cell(t, r, c_n).empty()) p.n_pixels = number(c_n, "n_pixels", true);
    if (c_exp >= 0 && !cell(t, r, c_exp).empty()) p.exposure = number(c_exp, "exposure", true);
    for (size_t c = 0; c < t.header.size(); ++c) p.conditions[t.header[c]] = cell(t, r, static_cast<int>(c));
    std::string rf = cell(t, r, c_rf);
    fs::path rp = resolve_listed_file(base, rf);
    if (rp.empty()) throw InputError(t.file, line + " column radiance_file", "file \"" + rf + "\" not found");
    auto it = radiance_files.find(rp.string());
    if (it == radiance_files.end()) it = radiance_files.emplace(rp.string(), read_numeric_csv(rp)).first;
    const CsvNumeric& rad = it->second;
    std::string col = cell(t, r, c_rc);
    int rc = rad.column(col);
    if (rc < 0) throw InputError(t.file, line + " column radiance_column", "\"" + col + "\" is not a column of " + rp.string());
    for (size_t k = 0; k < rad.rows.size(); ++k) {
      double nm = rad.rows[k][0], v = rad.rows[k][rc];
      std::string where = "line " + std::to_string(rad.lines[k]) + " column " + col;
      if (!std::isfinite(nm) || !std::isfinite(v)) throw InputError(rad.file, where, "NaN or infinite value");
      if (!p.nm.empty() && !(nm > p.nm.back())) throw InputError(rad.file, where, "wavelengths must increase");
      p.nm.push_back(nm);
      p.radiance.push_back(v);
    }
    if (p.nm.size() < 2) throw InputError(rad.file, col, "fewer than two wavelengths");
    out.patches.push_back(std::move(p));
  }
  if (out.patches.empty()) throw InputError(t.file, "", "no patches left after the selection");
  return out;
}

InputKind detect_input_kind(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path.string(), "", "no such file or folder");
  if (fs::is_directory(path, ec)) {
    if (fs::exists(path / "index.csv", ec)) return InputKind::kSpectra;
    if (fs::exists(path / "patches.csv", ec)) return InputKind::kCamera;
    throw InputError(path.string(), "", "the folder has neither index.csv (spectra) nor patches.csv (camera patches)");
  }
  CsvText t = read_csv(path);
  if (t.column("r_mean") >= 0) return InputKind::kCamera;
  return InputKind::kSpectra;
}

}  // namespace ofl
