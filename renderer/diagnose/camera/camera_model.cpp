#include "renderer/diagnose/camera/camera_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "renderer/core/errors/error.h"

namespace ofl {

namespace {
std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
}  // namespace

CameraProblem::CameraProblem(CameraPatchSet data, CameraModel model) : data_(std::move(data)), model_(std::move(model)) {
  double lo = 1e9, hi = 0;
  for (auto& p : data_.patches) {
    lo = std::min(lo, p.nm.front());
    hi = std::max(hi, p.nm.back());
  }
  const double step = model_.grid_step_nm, pad = 40;
  double gmin = std::max(step, std::floor((lo - pad) / step) * step);
  double gmax = gmin + step * std::ceil((hi + pad - gmin) / step);
  grid_ = WavelengthGrid{gmin, gmax, step};
  if (auto p = grid_.problem(); !p.empty()) throw InputError("model", "/grid_step_nm", p);
  const int N = grid_.size();
  filters_.assign(N, 1.0);
  for (auto& f : model_.filters) {
    auto t = tabulate(f, grid_);
    for (int i = 0; i < N; ++i) filters_[i] *= t[i];
  }
  nir_cut_ = model_.nir_cut_nm;
  if (!(nir_cut_ > 0)) {
    // Where the filter stack, past its red-most maximum region, falls below 5 % of its maximum.
    double mx = *std::max_element(filters_.begin(), filters_.end());
    nir_cut_ = grid_.max_nm;
    for (int i = N - 1; i >= 0; --i)
      if (filters_[i] >= 0.05 * mx && grid_.wavelength(i) > 550) { nir_cut_ = grid_.wavelength(i) + step; break; }
  }
  for (auto& p : data_.patches) {
    TabulatedSpectrum t{p.nm, p.radiance, Outside::kZero};
    radiance_.push_back(tabulate(table_spectrum(t, p.id), grid_));
    Eigen::VectorXd y(3);
    for (int c = 0; c < 3; ++c) y[c] = p.rgb[c] - model_.black_level;
    y_.push_back(y);
  }
  // Normalise so that the baseline gain starts near 1 and offsets/gammas are well scaled.
  ModelState s0;
  s0.base_theta = {1.0};
  norm_ = 1.0;
  auto S = sensor_signals(s0);
  double sm = 0, sy = 0;
  for (size_t i = 0; i < S.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      sm += S[i][c] * S[i][c];
      sy += S[i][c] * y_[i][c];
    }
  if (!(sm > 0)) throw InputError(data_.file, "radiance", "the sensor sees no signal from any patch (check QE, filters and wavelength ranges)");
  norm_ = sy > 0 ? sy / sm : 1.0;
  double ref = 0;
  for (auto& s : S)
    for (int c = 0; c < 3; ++c) ref += s[c] * norm_;
  s_ref_ = std::max(ref / (3.0 * S.size()), 1e-30);
  double scale = 0;
  for (auto& y : y_) scale = std::max(scale, y.cwiseAbs().maxCoeff());
  candidates_ = camera_candidates(model_.candidates, std::max(scale, 1e-9));
}

std::string CameraProblem::item_label(int i) const {
  auto& p = data_.patches[i];
  return p.id + " (line " + std::to_string(p.line) + ")";
}

std::string CameraProblem::condition(int i, const std::string& column) const {
  auto& c = data_.patches[i].conditions;
  auto it = c.find(column);
  return it == c.end() ? std::string() : it->second;
}

std::vector<ParamSpec> CameraProblem::baseline_params() const {
  ParamSpec g;
  g.name = "exposure_gain";
  g.unit = "relative";
  g.init = 1;
  g.lo = 1e-6;
  g.hi = 1e6;
  g.fd_step = 1e-5;
  return {g};
}

std::vector<std::array<double, 3>> CameraProblem::sensor_signals(const ModelState& s) const {
  double qe_shift = 0, nir = 0;
  for (auto& a : s.causes) {
    auto k = camera_cause(candidates_[a.candidate]);
    if (k == CameraCause::kQeShift) qe_shift = a.theta[0];
    if (k == CameraCause::kNirLeak) nir = a.theta[0];
  }
  const int N = grid_.size();
  std::array<std::vector<double>, 3> qe;
  for (int c = 0; c < 3; ++c) {
    Spectrum q = model_.qe[c];
    if (qe_shift != 0) {
      auto inner = q.eval;
      q.eval = [inner, qe_shift](double nm) { return inner(nm - qe_shift); };
      for (double& k : q.kinks) k += qe_shift;
    }
    qe[c] = tabulate(q, grid_);
  }
  std::vector<double> t = filters_;
  if (nir > 0)
    for (int i = 0; i < N; ++i)
      if (grid_.wavelength(i) > nir_cut_) t[i] += nir * (1.0 - t[i]);
  std::array<std::vector<double>, 3> w;
  for (int c = 0; c < 3; ++c) {
    w[c].resize(N);
    for (int i = 0; i < N; ++i) w[c][i] = t[i] * qe[c][i] * grid_.wavelength(i) * grid_.step_nm;
  }
  std::vector<std::array<double, 3>> S(radiance_.size());
  for (size_t p = 0; p < radiance_.size(); ++p)
    for (int c = 0; c < 3; ++c) {
      double v = 0;
      for (int i = 0; i < N; ++i) v += radiance_[p][i] * w[c][i];
      S[p][c] = v * data_.patches[p].exposure * norm_;
    }
  return S;
}

std::array<double, 3> CameraProblem::predict_one(int i, const ModelState& s, const std::vector<std::array<double, 3>>& S) const {
  std::array<double, 3> v = S[i];
  double gains[3] = {1, 1, 1}, offs[3] = {0, 0, 0}, gamma = 1;
  double X[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  bool xt = false;
  for (auto& a : s.causes) {
    switch (camera_cause(candidates_[a.candidate])) {
      case CameraCause::kGain: gains[0] = a.theta[0]; gains[2] = a.theta[1]; break;
      case CameraCause::kCrosstalk:
        xt = true;
        X[0][1] = a.theta[0]; X[0][2] = a.theta[1];
        X[1][0] = a.theta[2]; X[1][2] = a.theta[3];
        X[2][0] = a.theta[4]; X[2][1] = a.theta[5];
        break;
      case CameraCause::kOffset: for (int c = 0; c < 3; ++c) offs[c] = a.theta[c]; break;
      case CameraCause::kNonlinearity: gamma = a.theta[0]; break;
      default: break;
    }
  }
  if (xt) {
    // Crosstalk moves signal, it does not create it: what a channel hands to the others it loses
    // (columns of the mixing matrix sum to 1).
    std::array<double, 3> m{};
    for (int c = 0; c < 3; ++c) {
      double keep = 1.0;
      for (int d = 0; d < 3; ++d) keep -= (d != c) ? X[d][c] : 0.0;
      m[c] = keep * v[c];
      for (int d = 0; d < 3; ++d)
        if (d != c) m[c] += X[c][d] * v[d];
    }
    v = m;
  }
  double g = s.base_theta.empty() ? 1.0 : s.base_theta[0];
  for (int c = 0; c < 3; ++c) {
    double x = std::max(v[c], 0.0);
    double lin = gamma == 1 ? x : s_ref_ * std::pow(x / s_ref_, gamma);
    v[c] = g * gains[c] * lin + offs[c];
  }
  return v;
}

std::vector<ItemFit> CameraProblem::evaluate(const ModelState& state, const std::vector<int>& items) const {
  auto S = sensor_signals(state);
  std::vector<ItemFit> out;
  out.reserve(items.size());
  for (int i : items) {
    auto v = predict_one(i, state, S);
    ItemFit f;
    f.measured = y_[i];
    f.predicted.resize(3);
    for (int c = 0; c < 3; ++c) f.predicted[c] = v[c];
    f.residual = f.measured - f.predicted;
    out.push_back(std::move(f));
  }
  return out;
}

std::vector<std::array<double, 3>> CameraProblem::predict(const ModelState& state) const {
  auto S = sensor_signals(state);
  std::vector<std::array<double, 3>> v;
  for (int i = 0; i < num_items(); ++i) v.push_back(predict_one(i, state, S));
  return v;
}

double CameraProblem::fallback_noise_variance() const {
  double s = 0;
  int n = 0;
  for (auto& p : data_.patches)
    for (int c = 0; c < 3; ++c)
      if (p.sd[c] >= 0 && p.n_pixels > 0) {
        s += p.sd[c] * p.sd[c] / p.n_pixels;
        ++n;
      }
  return n ? s / n : -1;
}

double CameraProblem::centred_sum_of_squares(int i) const {
  double ss = 0;
  for (int c = 0; c < 3; ++c) {
    double m = 0;
    for (auto& y : y_) m += y[c];
    m /= y_.size();
    ss += (y_[i][c] - m) * (y_[i][c] - m);
  }
  return ss;
}

std::string CameraProblem::plain_words(const CandidateSpec& c, const std::vector<double>& th, const std::vector<double>& u,
                                       const std::vector<DerivedParam>&) const {
  auto pm = [](double v, double e, const char* f) { return fmt(f, v) + " +/- " + fmt(f, e); };
  switch (camera_cause(c)) {
    case CameraCause::kGain:
      return "Relative to green, the red and blue channels are " + pm(th[0], u[0], "%.3f") + " and " + pm(th[1], u[1], "%.3f") +
             " times as sensitive as the stated QE curves say.";
    case CameraCause::kCrosstalk:
      return "Signal of one channel is counted in another: red gets " + pm(100 * th[0], 100 * u[0], "%.1f") + "% of green and " +
             pm(100 * th[1], 100 * u[1], "%.1f") + "% of blue; green gets " + pm(100 * th[2], 100 * u[2], "%.1f") + "% of red and " +
             pm(100 * th[3], 100 * u[3], "%.1f") + "% of blue; blue gets " + pm(100 * th[4], 100 * u[4], "%.1f") + "% of red and " +
             pm(100 * th[5], 100 * u[5], "%.1f") + "% of green.";
    case CameraCause::kOffset:
      return "Each channel carries an offset (black level not removed or wrong): R " + pm(th[0], u[0], "%.2f") + ", G " +
             pm(th[1], u[1], "%.2f") + ", B " + pm(th[2], u[2], "%.2f") + " DN.";
    case CameraCause::kNonlinearity:
      return "The sensor responds as signal^" + pm(th[0], u[0], "%.3f") + " instead of linearly.";
    case CameraCause::kQeShift:
      return "The sensor's QE curves sit " + pm(th[0], u[0], "%+.2f") + " nm from the stated ones.";
    case CameraCause::kNirLeak:
      return "The IR-cut filter passes " + pm(100 * th[0], 100 * u[0], "%.2f") + "% of the light beyond " + fmt("%.0f", nir_cut_) +
             " nm.";
  }
  return c.title;
}

}  // namespace ofl
