#include "renderer/spectral/chromophores/eem.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/files/csv.h"
#include "renderer/core/errors/error.h"

namespace ofl {

std::vector<double> GridEem::photon_albedo() const {
  int N = n();
  std::vector<double> a(N, 0.0);
  for (int em = 0; em < N; ++em)
    for (int ex = 0; ex < N; ++ex) a[ex] += at(em, ex);
  for (double& v : a) v *= grid.step_nm;
  return a;
}


std::vector<double> GridEem::apply(const std::vector<double>& e) const {
  int N = n();
  std::vector<double> out(N, 0.0);
  for (int em = 0; em < N; ++em) {
    double s = 0;
    for (int ex = 0; ex < em; ++ex) s += at(em, ex) * e[ex];
    out[em] = s * grid.step_nm;
  }
  return out;
}

Eem read_eem_csv(const std::filesystem::path& file) {
  CsvNumeric t;
  try {
    t = read_numeric_csv(file);
  } catch (const InputError& e) {
    // The header cells after the first are excitation wavelengths; the rest are numbers.
    throw;
  }
  Eem e;
  if (t.header.size() < 3) throw InputError(t.file, "header", "an EEM needs at least two excitation columns");
  for (size_t c = 1; c < t.header.size(); ++c) {
    char* end = nullptr;
    double v = std::strtod(t.header[c].c_str(), &end);
    if (end == t.header[c].c_str() || !(v > 0))
      throw InputError(t.file, "line 1 column " + std::to_string(c + 1), "excitation wavelength \"" + t.header[c] + "\" is not a number");
    if (!e.ex_nm.empty() && !(v > e.ex_nm.back()))
      throw InputError(t.file, "line 1 column " + std::to_string(c + 1), "excitation wavelengths must increase");
    e.ex_nm.push_back(v);
  }
  for (size_t r = 0; r < t.rows.size(); ++r) {
    std::string where = "line " + std::to_string(t.lines[r]);
    double em = t.rows[r][0];
    if (!std::isfinite(em) || !(em > 0)) throw InputError(t.file, where, "emission wavelength is not a number");
    if (!e.em_nm.empty() && !(em > e.em_nm.back())) throw InputError(t.file, where, "emission wavelengths must increase");
    e.em_nm.push_back(em);
    for (size_t c = 1; c < t.rows[r].size(); ++c) {
      double v = t.rows[r][c];
      if (!std::isfinite(v))
        throw InputError(t.file, where + " column " + std::to_string(c + 1), "entry is NaN (excitation " + t.header[c] + " nm)");
      if (v < 0)
        throw InputError(t.file, where + " column " + std::to_string(c + 1),
                         "negative entry " + std::to_string(v) + " (excitation " + t.header[c] + " nm)");
      e.values.push_back(v);
    }
  }
  if (e.em_nm.size() < 2) throw InputError(t.file, "", "an EEM needs at least two emission rows");
  return e;
}

namespace {
// The mean over every bin of the grid of the piecewise-linear function through (x, y), zero outside
// [x.front(), x.back()]: exact, from its antiderivative at the bin edges, in one pass over the
// edges and knots (x increasing). Evaluating the spectrum per bin instead made a fine grid's
// resampling quadratic with a large constant: minutes for a 1 nm grid under a sanitizer.
std::vector<double> bin_means(const std::vector<double>& x, const std::vector<double>& y, const WavelengthGrid& grid) {
  const size_t n = x.size();
  std::vector<double> cum(n, 0.0);  // integral from x[0] to x[j]
  for (size_t j = 1; j < n; ++j) cum[j] = cum[j - 1] + 0.5 * (y[j - 1] + y[j]) * (x[j] - x[j - 1]);
  size_t j = 0;  // the knot at or below the last edge asked for
  auto F = [&](double t) {
    if (t <= x.front()) return 0.0;
    if (t >= x.back()) return cum.back();
    while (j + 1 < n && x[j + 1] <= t) ++j;
    const double h = x[j + 1] - x[j], d = t - x[j];
    return cum[j] + d * (y[j] + 0.5 * d * (y[j + 1] - y[j]) / h);
  };
  const int N = grid.size();
  std::vector<double> out(N);
  double lo = F(grid.bin_lo(0));
  for (int i = 0; i < N; ++i) {
    const double hi = F(grid.bin_hi(i));
    out[i] = (hi - lo) / grid.step_nm;
    lo = hi;
  }
  return out;
}
}  // namespace

GridEem resample(const Eem& e, const WavelengthGrid& grid) {
  int N = grid.size();
  size_t nem = e.em_nm.size(), nex = e.ex_nm.size();
  // Along emission first: for each excitation column, bin means on the grid.
  std::vector<double> tmp(static_cast<size_t>(N) * nex);
  std::vector<double> col(nem);
  for (size_t c = 0; c < nex; ++c) {
    for (size_t r = 0; r < nem; ++r) col[r] = e.at(r, c);
    const std::vector<double> m = bin_means(e.em_nm, col, grid);
    for (int i = 0; i < N; ++i) tmp[static_cast<size_t>(i) * nex + c] = m[i];
  }
  GridEem g{grid, std::vector<double>(static_cast<size_t>(N) * N, 0.0)};
  std::vector<double> row(nex);
  for (int em = 0; em < N; ++em) {
    for (size_t c = 0; c < nex; ++c) row[c] = tmp[static_cast<size_t>(em) * nex + c];
    bool any = std::any_of(row.begin(), row.end(), [](double v) { return v != 0; });
    if (!any) continue;
    const std::vector<double> m = bin_means(e.ex_nm, row, grid);
    for (int ex = 0; ex < em; ++ex) g.at(em, ex) = m[ex];
  }
  return g;
}

GridEem eem_from_pair(const Spectrum& excitation, const Spectrum& emission, const WavelengthGrid& grid) {
  auto x = tabulate(excitation, grid);
  auto e = tabulate(emission, grid);
  double norm = integrate(e, grid);
  int N = grid.size();
  GridEem g{grid, std::vector<double>(static_cast<size_t>(N) * N, 0.0)};
  if (norm <= 0) return g;
  for (int em = 0; em < N; ++em)
    for (int ex = 0; ex < em; ++ex) g.at(em, ex) = x[ex] * e[em] / norm;
  return g;
}

EemPeaks find_peaks(const GridEem& eem) {
  EemPeaks p;
  auto a = eem.photon_albedo();
  int best = static_cast<int>(std::max_element(a.begin(), a.end()) - a.begin());
  p.excitation_nm = eem.grid.wavelength(best);
  p.max_albedo = a[best];
  int bem = 0;
  for (int em = 0; em < eem.n(); ++em)
    if (eem.at(em, best) > eem.at(bem, best)) bem = em;
  p.emission_nm = eem.grid.wavelength(bem);
  return p;
}

}  // namespace ofl
