#include "renderer/camera/sensor/photon_transfer.h"

#include <cmath>
#include <stdexcept>

namespace ofl {
namespace {

template <class F>
void for_pixels(size_t n, const std::vector<size_t>& sel, F&& f) {
  if (sel.empty())
    for (size_t i = 0; i < n; ++i) f(i);
  else
    for (size_t i : sel) f(i);
}

struct PairStats {
  double mean = 0, temporal_var = 0;
};

PairStats pair_stats(const FramePair& p, const std::vector<size_t>& sel) {
  if (p.a.size() != p.b.size() || p.a.empty()) throw std::invalid_argument("photon transfer: frame sizes differ");
  double sum = 0, dsum = 0, dsum2 = 0;
  size_t n = 0;
  for_pixels(p.a.size(), sel, [&](size_t i) {
    double a = p.a[i], b = p.b[i];
    sum += a + b;
    double d = a - b;
    dsum += d;
    dsum2 += d * d;
    ++n;
  });
  PairStats s;
  s.mean = sum / (2.0 * n);
  double dmean = dsum / n;
  s.temporal_var = (dsum2 / n - dmean * dmean) / 2.0;  // var(A - B) / 2
  return s;
}

// Mean and spatial variance of the per-pixel average of L frames, and the temporal variance from
// the first two frames.
struct AverageStats {
  double mean = 0, spatial_var = 0, temporal_var = 0;
};

AverageStats average_stats(const std::vector<RawPixels>& frames, const std::vector<size_t>& sel) {
  if (frames.size() < 2) throw std::invalid_argument("non-uniformity: need at least two frames");
  size_t n_px = frames[0].size();
  double L = static_cast<double>(frames.size());
  double sum = 0, sum2 = 0;
  size_t n = 0;
  for_pixels(n_px, sel, [&](size_t i) {
    double m = 0;
    for (const auto& f : frames) m += f[i];
    m /= L;
    sum += m;
    sum2 += m * m;
    ++n;
  });
  AverageStats s;
  s.mean = sum / n;
  double var_of_mean = (sum2 / n - s.mean * s.mean) * n / (n - 1.0);
  // Temporal variance from all frames: per-pixel sample variance, averaged over pixels.
  double tv = 0;
  for_pixels(n_px, sel, [&](size_t i) {
    double m = 0, m2 = 0;
    for (const auto& f : frames) {
      m += f[i];
      m2 += static_cast<double>(f[i]) * f[i];
    }
    tv += (m2 - m * m / L) / (L - 1.0);
  });
  s.temporal_var = tv / n;
  s.spatial_var = std::max(0.0, var_of_mean - s.temporal_var / L);
  return s;
}

}  // namespace

PhotonTransferResult analyse_photon_transfer(const FramePair& dark, const std::vector<FramePair>& series,
                                             const std::vector<size_t>& sel) {
  PhotonTransferResult r;
  PairStats d = pair_stats(dark, sel);
  r.dark_mean_dn = d.mean;
  r.dark_variance_dn = d.temporal_var;
  double best = -1;
  for (size_t k = 0; k < series.size(); ++k) {
    PairStats s = pair_stats(series[k], sel);
    PtcPoint p{s.mean - d.mean, s.temporal_var - d.temporal_var};
    r.points.push_back(p);
    if (p.variance_dn > best) {
      best = p.variance_dn;
      r.saturation_index = static_cast<int>(k);
    }
  }
  if (r.saturation_index < 0) return r;
  double mu_sat = r.points[r.saturation_index].mean_dn;
  double sxy = 0, sxx = 0;
  for (const auto& p : r.points) {
    if (p.mean_dn <= 0 || p.mean_dn > 0.7 * mu_sat) continue;
    sxy += p.mean_dn * p.variance_dn;
    sxx += p.mean_dn * p.mean_dn;
    ++r.fit_points;
  }
  if (sxx <= 0) return r;
  r.system_gain_dn_per_e = sxy / sxx;
  r.read_noise_e = std::sqrt(std::max(0.0, d.temporal_var - 1.0 / 12.0)) / r.system_gain_dn_per_e;
  r.saturation_capacity_e = mu_sat / r.system_gain_dn_per_e;
  const PtcPoint& last = r.points.back();
  if (last.variance_dn + d.temporal_var < 0.02 * best) r.full_well_plateau_e = last.mean_dn / r.system_gain_dn_per_e;
  return r;
}

NonUniformity analyse_nonuniformity(const std::vector<RawPixels>& dark, const std::vector<RawPixels>& bright,
                                    double K, const std::vector<size_t>& sel) {
  AverageStats d = average_stats(dark, sel), b = average_stats(bright, sel);
  NonUniformity u;
  u.dsnu_e = std::sqrt(d.spatial_var) / K;
  double signal = b.mean - d.mean;
  u.prnu = signal > 0 ? std::sqrt(std::max(0.0, b.spatial_var - d.spatial_var)) / signal : 0.0;
  return u;
}

}  // namespace ofl
