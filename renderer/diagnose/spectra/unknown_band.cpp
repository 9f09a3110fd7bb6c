#include "renderer/diagnose/spectra/unknown_band.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "renderer/numerics/nnls.h"
#include "renderer/plot/charts.h"

namespace ofl {

namespace {

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const size_t n = std::min(a.size(), b.size());
  double ma = 0, mb = 0;
  for (size_t i = 0; i < n; ++i) { ma += a[i]; mb += b[i]; }
  ma /= n;
  mb /= n;
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0;
}

// Full width at half maximum around the peak (linear interpolation of the crossings).
double fwhm(const std::vector<double>& x, const std::vector<double>& y, size_t peak) {
  double half = 0.5 * y[peak];
  double lo = x.front(), hi = x.back();
  for (size_t i = peak; i > 0; --i)
    if (y[i - 1] < half) { lo = x[i - 1] + (half - y[i - 1]) / (y[i] - y[i - 1]) * (x[i] - x[i - 1]); break; }
  for (size_t i = peak; i + 1 < y.size(); ++i)
    if (y[i + 1] < half) { hi = x[i] + (y[i] - half) / (y[i] - y[i + 1]) * (x[i + 1] - x[i]); break; }
  return hi - lo;
}

// Each library fluorophore's emission under its most efficient excitation, sampled at nm.
std::vector<double> library_emission(const SpectraProblem& p, int k, const std::vector<double>& nm) {
  const GridEem& e = p.fluorophore_eem(k);
  auto a = e.photon_albedo();
  int ex = static_cast<int>(std::max_element(a.begin(), a.end()) - a.begin());
  std::vector<double> out;
  for (double w : nm) {
    double x = (w - e.grid.min_nm) / e.grid.step_nm;
    int i = std::clamp(static_cast<int>(std::floor(x)), 0, e.n() - 2);
    double t = std::clamp(x - i, 0.0, 1.0);
    double v0 = e.at(i, ex) / e.grid.wavelength(i), v1 = e.at(i + 1, ex) / e.grid.wavelength(i + 1);
    out.push_back(v0 * (1 - t) + v1 * t);
  }
  return out;
}

}  // namespace

UnknownBandEstimate estimate_unknown_band(const SpectraProblem& p, const ModelState& state, int iterations) {
  UnknownBandEstimate out;
  const int M = p.num_items();
  if (M < 2) return out;
  // Items on the first item's abscissa only (the shape is one vector).
  std::vector<int> items;
  const std::vector<double> nm = p.abscissa(0);
  for (int i = 0; i < M; ++i)
    if (p.abscissa(i) == nm) items.push_back(i);
  if (items.size() < 2) return out;
  const Eigen::Index L = static_cast<Eigen::Index>(nm.size());
  std::vector<Eigen::MatrixXd> A;
  for (int i : items) A.push_back(p.design(state, i).A);

  // Start: the positive part of the mean residual of the model as it is.
  Eigen::VectorXd s = Eigen::VectorXd::Zero(L);
  for (size_t q = 0; q < items.size(); ++q) {
    NnlsResult r = nnls(A[q], p.measured(items[q]));
    Eigen::VectorXd res = p.measured(items[q]) - A[q] * r.x;
    out.rss_before += res.squaredNorm();
    s += res;
  }
  s = s.cwiseMax(0.0);
  if (!(s.maxCoeff() > 0)) return out;
  s /= s.maxCoeff();

  std::vector<double> amp(items.size(), 0.0);
  std::vector<Eigen::VectorXd> rest(items.size());
  for (int it = 0; it < iterations; ++it) {
    // Amplitudes: NNLS on [model columns, s] per spectrum.
    for (size_t q = 0; q < items.size(); ++q) {
      Eigen::MatrixXd B(L, A[q].cols() + 1);
      B << A[q], s;
      NnlsResult r = nnls(B, p.measured(items[q]));
      amp[q] = r.x[A[q].cols()];
      rest[q] = p.measured(items[q]) - A[q] * r.x.head(A[q].cols());
    }
    // Shape: least squares over all spectra, clipped at zero, peak-normalised.
    Eigen::VectorXd num = Eigen::VectorXd::Zero(L);
    double den = 0;
    for (size_t q = 0; q < items.size(); ++q) { num += amp[q] * rest[q]; den += amp[q] * amp[q]; }
    if (!(den > 0)) return out;
    Eigen::VectorXd sn = (num / den).cwiseMax(0.0);
    if (!(sn.maxCoeff() > 0)) return out;
    double scale = sn.maxCoeff();
    sn /= scale;
    double change = (sn - s).norm() / std::max(1e-12, s.norm());
    s = sn;
    out.iterations = it + 1;
    if (change < 1e-6) break;
  }
  double frac = 0;
  out.rss_after = 0;
  for (size_t q = 0; q < items.size(); ++q) {
    Eigen::MatrixXd B(L, A[q].cols() + 1);
    B << A[q], s;
    NnlsResult r = nnls(B, p.measured(items[q]));
    Eigen::VectorXd pred = B * r.x;
    out.rss_after += (p.measured(items[q]) - pred).squaredNorm();
    double tot = pred.mean();
    frac += tot > 0 ? (s * r.x[A[q].cols()]).mean() / tot : 0;
  }
  out.mean_fraction = frac / items.size();
  out.nm = nm;
  out.shape.assign(s.data(), s.data() + s.size());
  size_t pk = static_cast<size_t>(std::max_element(out.shape.begin(), out.shape.end()) - out.shape.begin());
  out.peak_nm = nm[pk];
  out.fwhm_nm = fwhm(nm, out.shape, pk);
  for (size_t k = 0; k < p.fluorophore_names().size(); ++k)
    out.closest.push_back({p.fluorophore_names()[k], pearson(out.shape, library_emission(p, static_cast<int>(k), nm))});
  std::sort(out.closest.begin(), out.closest.end(), [](auto& a, auto& b) { return a.second > b.second; });
  if (out.closest.size() > 3) out.closest.resize(3);
  out.found = true;
  return out;
}

}  // namespace ofl

namespace ofl {

UnknownBandReport unknown_band_report(const SpectraProblem& p, const Diagnosis& d) {
  UnknownBandReport r;
  ModelState s = d.final_fit.state;
  for (size_t k = 0; k < s.causes.size(); ++k)
    if (p.candidates()[s.causes[k].candidate].name == "unknown_band") {
      s.causes.erase(s.causes.begin() + static_cast<long>(k));
      r.accepted = true;
      break;
    }
  if (!r.accepted && !(d.rmse_extended_heldout > 2 * d.floor.rmse)) return r;
  r.estimate = estimate_unknown_band(p, s);
  return r;
}

nlohmann::json unknown_band_json(const UnknownBandReport& r) {
  const auto& e = r.estimate;
  nlohmann::json close = nlohmann::json::array();
  for (auto& [n, c] : e.closest) close.push_back({{"fluorophore", n}, {"correlation", c}});
  return {{"found", e.found}, {"accepted", r.accepted}, {"peak_nm", e.peak_nm}, {"fwhm_nm", e.fwhm_nm},
          {"mean_fraction", e.mean_fraction}, {"rss_before", e.rss_before}, {"rss_after", e.rss_after},
          {"closest_library_spectra", close}, {"nm", e.nm}, {"shape", e.shape}, {"iterations", e.iterations}};
}

std::string unknown_band_text(const UnknownBandReport& r) {
  const auto& e = r.estimate;
  if (!e.found) return "";
  std::ostringstream o;
  char b[256];
  std::snprintf(b, sizeof b, "an emission band at %.0f nm, FWHM %.0f nm, not in the library (%.1f %% of the signal on average)", e.peak_nm,
                e.fwhm_nm, 100 * e.mean_fraction);
  o << "\nunknown-band finder (non-negative curve resolution of the residuals): " << b;
  o << (r.accepted ? "; its held-out gain is that of the accepted cause unknown_band above" : "; residual structure only, no held-out claim");
  o << "\n   closest library spectra (correlation):";
  for (auto& [n, c] : e.closest) {
    std::snprintf(b, sizeof b, " %s %.2f;", n.c_str(), c);
    o << b;
  }
  o << "\n";
  return o.str();
}

VectorPlot unknown_band_plot(const UnknownBandReport& r) {
  Plot pl;
  pl.title = "unknown band: shape estimated from the residuals (as recorded, peak = 1)";
  pl.xlabel = "wavelength (nm)";
  pl.ylabel = "relative radiance";
  PlotSeries s;
  s.x = r.estimate.nm;
  s.y = r.estimate.shape;
  s.label = "estimated band";
  pl.series.push_back(s);
  return line_chart(pl);
}

// The spectra problem's one section of its own (diagnose_problem.h, ReportSection): the estimate
// of the unknown band, when there is one, as JSON, text and a figure.
std::vector<ReportSection> SpectraProblem::report_sections(const Diagnosis& d) const {
  UnknownBandReport ub = unknown_band_report(*this, d);
  if (!ub.estimate.found) return {};
  ReportSection s;
  s.key = "unknown_band_estimate";
  s.json = unknown_band_json(ub);
  s.text = unknown_band_text(ub);
  s.figure_name = "unknown_band";
  s.figure = unknown_band_plot(ub);
  return {std::move(s)};
}

}  // namespace ofl
