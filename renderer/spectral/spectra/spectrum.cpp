#include "renderer/spectral/spectra/spectrum.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "renderer/core/files/csv.h"
#include "renderer/core/errors/error.h"
#include "renderer/formats/mat_spectrum.h"
#include "renderer/formats/mat_file.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {

double TabulatedSpectrum::eval(double wl) const {
  if (wl <= nm.front()) return (outside == Outside::kClamp || wl == nm.front()) ? value.front() : 0.0;
  if (wl >= nm.back()) return (outside == Outside::kClamp || wl == nm.back()) ? value.back() : 0.0;
  size_t i = std::upper_bound(nm.begin(), nm.end(), wl) - nm.begin();
  double t = (wl - nm[i - 1]) / (nm[i] - nm[i - 1]);
  return value[i - 1] * (1 - t) + value[i] * t;
}

Spectrum constant_spectrum(double v) {
  std::ostringstream d;
  d << "constant " << v;
  return {[v](double) { return v; }, {}, d.str()};
}

Spectrum table_spectrum(TabulatedSpectrum t, std::string description) {
  auto kinks = t.nm;
  auto shared = std::make_shared<TabulatedSpectrum>(std::move(t));
  return {[shared](double wl) { return shared->eval(wl); }, std::move(kinks), std::move(description)};
}

Spectrum gaussian_spectrum(double peak_nm, double fwhm_nm) {
  double sigma = fwhm_nm / (2.0 * std::sqrt(2.0 * std::log(2.0)));
  std::ostringstream d;
  d << "gaussian peak " << peak_nm << " nm, FWHM " << fwhm_nm << " nm";
  return {[=](double wl) { double x = (wl - peak_nm) / sigma; return std::exp(-0.5 * x * x); }, {}, d.str()};
}

double planck_radiance(double nm, double kelvin) {
  double l = nm * 1e-9;
  double c1 = 2.0 * kPlanck * kSpeedOfLight * kSpeedOfLight;
  double c2 = kPlanck * kSpeedOfLight / kBoltzmann;
  return c1 / (l * l * l * l * l) / std::expm1(c2 / (l * kelvin)) * 1e-9;  // per nm
}

Spectrum blackbody_spectrum(double kelvin) {
  double peak_nm = 2.897771955e6 / kelvin;  // Wien's displacement law
  double norm = 1.0 / planck_radiance(peak_nm, kelvin);
  std::ostringstream d;
  d << "blackbody " << kelvin << " K";
  return {[=](double wl) { return planck_radiance(wl, kelvin) * norm; }, {}, d.str()};
}

Spectrum product_spectrum(const std::vector<Spectrum>& factors) {
  std::vector<double> kinks;
  std::string desc;
  for (auto& f : factors) {
    kinks.insert(kinks.end(), f.kinks.begin(), f.kinks.end());
    desc += (desc.empty() ? "" : " x ") + f.description;
  }
  std::sort(kinks.begin(), kinks.end());
  kinks.erase(std::unique(kinks.begin(), kinks.end()), kinks.end());
  auto fs = factors;
  return {[fs](double wl) {
            double v = 1.0;
            for (auto& f : fs) v *= f.eval(wl);
            return v;
          },
          std::move(kinks), desc};
}

Spectrum sum_spectrum(const std::vector<Spectrum>& terms) {
  std::vector<double> kinks;
  std::string desc;
  for (auto& f : terms) {
    kinks.insert(kinks.end(), f.kinks.begin(), f.kinks.end());
    desc += (desc.empty() ? "" : " + ") + f.description;
  }
  std::sort(kinks.begin(), kinks.end());
  kinks.erase(std::unique(kinks.begin(), kinks.end()), kinks.end());
  auto ts = terms;
  return {[ts](double wl) {
            double v = 0.0;
            for (auto& f : ts) v += f.eval(wl);
            return v;
          },
          std::move(kinks), desc};
}

Spectrum scaled_spectrum(Spectrum s, double factor) {
  auto inner = s.eval;
  s.eval = [inner, factor](double wl) { return factor * inner(wl); };
  return s;
}

double average(const Spectrum& s, double a, double b) {
  // Trapezoid rule on the kinks inside [a, b] plus a uniform subdivision; exact for piecewise
  // linear tables, and 16 sub-intervals resolve smooth shapes (Gaussians, filters) to <1e-4.
  std::vector<double> x;
  constexpr int kSub = 16;
  for (int k = 0; k <= kSub; ++k) x.push_back(a + (b - a) * k / kSub);
  auto lo = std::upper_bound(s.kinks.begin(), s.kinks.end(), a);
  auto hi = std::lower_bound(s.kinks.begin(), s.kinks.end(), b);
  x.insert(x.end(), lo, hi);
  std::sort(x.begin(), x.end());
  // Each piece is evaluated just inside its ends, so a jump at a kink (a table that is zero outside
  // its range) is integrated exactly instead of as a ramp.
  double sum = 0;
  for (size_t i = 1; i < x.size(); ++i) {
    double h = x[i] - x[i - 1];
    if (h <= 0) continue;
    double d = 1e-9 * h;
    sum += 0.5 * (s.eval(x[i - 1] + d) + s.eval(x[i] - d)) * h;
  }
  return sum / (b - a);
}

std::vector<double> tabulate(const Spectrum& s, const WavelengthGrid& grid) {
  std::vector<double> v(grid.size());
  for (int i = 0; i < grid.size(); ++i) v[i] = average(s, grid.bin_lo(i), grid.bin_hi(i));
  return v;
}

double integrate(const std::vector<double>& values, const WavelengthGrid& grid) {
  double s = 0;
  for (double v : values) s += v;
  return s * grid.step_nm;
}

CsvNumeric read_spectrum_table(const std::filesystem::path& file) {
  return is_mat_file(file) ? read_spectrum_mat(file) : read_numeric_csv(file);
}

TabulatedSpectrum read_spectrum_csv(const std::filesystem::path& file, const SpectrumCsvOptions& opt) {
  CsvNumeric t = read_spectrum_table(file);
  const std::string row_name = is_mat_file(file) ? "data row " : "line ";
  if (t.header.size() < 2) throw InputError(t.file, "", "a spectrum needs a wavelength column and a value column");
  int col;
  if (opt.column.empty()) {
    if (t.header.size() != 2)
      throw InputError(t.file, "", "has " + std::to_string(t.header.size() - 1) +
                                       " value columns; name one with \"column\"");
    col = 1;
  } else {
    col = t.require_column(opt.column);
  }
  TabulatedSpectrum s;
  s.outside = opt.outside;
  for (size_t r = 0; r < t.rows.size(); ++r) {
    std::string where = row_name + std::to_string(t.lines[r]);
    double wl = t.rows[r][0], v = t.rows[r][col];
    if (!std::isfinite(wl)) throw InputError(t.file, where, "wavelength is not a number");
    if (!s.nm.empty() && !(wl > s.nm.back()))
      throw InputError(t.file, where, "wavelengths must increase (" + std::to_string(wl) + " nm after " +
                                          std::to_string(s.nm.back()) + " nm)");
    if (!std::isfinite(v)) throw InputError(t.file, where + " column \"" + t.header[col] + "\"", "value is NaN or infinite");
    v *= opt.scale;
    if (v < 0) {
      if (opt.clip_negative) v = 0;
      else if (!opt.allow_negative)
        throw InputError(t.file, where + " column \"" + t.header[col] + "\"",
                         "negative value " + std::to_string(v) + " (set \"clip_negative\": true to clip noise)");
    }
    s.nm.push_back(wl);
    s.value.push_back(v);
  }
  if (s.nm.size() < 2) throw InputError(t.file, "", "a spectrum needs at least two rows");
  return s;
}

}  // namespace ofl
