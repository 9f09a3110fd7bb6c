#include "renderer/diagnose/model_extensions.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ofl {

namespace {
ParamSpec param(std::string name, std::string unit, double init, double lo, double hi, double step,
                std::vector<double> starts = {}) {
  ParamSpec p;
  p.name = std::move(name);
  p.unit = std::move(unit);
  p.init = init;
  p.lo = lo;
  p.hi = hi;
  p.fd_step = step;
  p.starts = std::move(starts);
  return p;
}
}  // namespace

std::vector<CandidateSpec> spectra_candidates(const SpectraCandidateOptions& o, const std::vector<std::string>& extra) {
  std::vector<CandidateSpec> c;
  if (o.blood) {
    // Starting grid spans optical densities at 577 nm from 0 to about 1.5 (oxy, 55000 cm^-1/M).
    std::vector<double> s = {0, 2, 8, 25};
    c.push_back({"blood_absorption", "blood_absorption", "blood absorption (oxy/deoxy hemoglobin, Beer-Lambert)",
                 {param("oxy_uM_cm", "umol/L*cm", 0, 0, 300, 0.05, s), param("deoxy_uM_cm", "umol/L*cm", 0, 0, 300, 0.05, s)},
                 0});
  }
  if (o.extra_fluorophore)
    for (auto& n : extra)
      c.push_back({"extra_fluorophore:" + n, "extra_fluorophore", "an extra fluorophore (" + n + ")", {}, 1});
  if (o.shift)
    c.push_back({"wavelength_shift", "wavelength_shift", "wavelength calibration shift",
                 {param("delta_nm", "nm", 0, -10, 10, 0.02, {-3, -1, 0, 1, 3})}, 0});
  if (o.bandwidth)
    c.push_back({"bandwidth", "bandwidth", "spectral bandwidth (extra Gaussian blur)",
                 {param("fwhm_nm", "nm", 0, 0, 40, 0.05, {0, 3, 6, 10, 16})}, 0});
  if (o.broadening)
    c.push_back({"emission_broadening", "emission_broadening", "fluorescence bands broader than the library's",
                 {param("fwhm_nm", "nm", 0, 0, 60, 0.05, {0, 5, 10, 20, 30})}, 0});
  if (o.stray)
    c.push_back({"stray_light", "stray_light", "stray-light offset (flat, proportional to the signal)",
                 {param("fraction", "of the mean signal", 0, 0, 1, 1e-4, {0, 0.01, 0.03, 0.1})}, 0});
  if (o.leak)
    c.push_back({"longpass_leak", "longpass_leak", "excitation leak through the long-pass filter", {}, 1});
  if (o.edge)
    c.push_back({"longpass_edge", "longpass_edge", "long-pass filter edge shifted",
                 {param("shift_nm", "nm", 0, -20, 20, 0.02, {-6, -3, 0, 3, 6})}, 0});
  return c;
}

SpectraCause spectra_cause(const CandidateSpec& c) {
  if (c.name == "blood_absorption") return SpectraCause::kBlood;
  if (c.name == "extra_fluorophore") return SpectraCause::kExtraFluorophore;
  if (c.name == "wavelength_shift") return SpectraCause::kShift;
  if (c.name == "bandwidth") return SpectraCause::kBandwidth;
  if (c.name == "emission_broadening") return SpectraCause::kBroadening;
  if (c.name == "stray_light") return SpectraCause::kStray;
  if (c.name == "longpass_leak") return SpectraCause::kLeak;
  if (c.name == "longpass_edge") return SpectraCause::kEdge;
  throw std::logic_error("not a spectra candidate: " + c.id);
}

std::string extra_fluorophore_name(const CandidateSpec& c) {
  auto p = c.id.find(':');
  return p == std::string::npos ? std::string() : c.id.substr(p + 1);
}

std::vector<CandidateSpec> camera_candidates(const CameraCandidateOptions& o, double scale) {
  std::vector<CandidateSpec> c;
  if (o.gain)
    c.push_back({"channel_gain", "channel_gain", "per-channel gain (white balance / QE scale)",
                 {param("gain_r", "relative to green", 1, 0.05, 20, 1e-4, {0.8, 1, 1.25}),
                  param("gain_b", "relative to green", 1, 0.05, 20, 1e-4, {0.8, 1, 1.25})},
                 0});
  if (o.crosstalk) {
    std::vector<ParamSpec> p;
    const char* names[6] = {"r_from_g", "r_from_b", "g_from_r", "g_from_b", "b_from_r", "b_from_g"};
    for (auto* n : names) p.push_back(param(n, "fraction", 0, 0, 0.5, 1e-4));
    c.push_back({"crosstalk", "crosstalk", "channel crosstalk (3x3 mixing)", p, 0});
  }
  if (o.offset)
    c.push_back({"offset", "offset", "per-channel offset (black level)",
                 {param("offset_r", "DN", 0, -scale, scale, 1e-4 * scale), param("offset_g", "DN", 0, -scale, scale, 1e-4 * scale),
                  param("offset_b", "DN", 0, -scale, scale, 1e-4 * scale)},
                 0});
  if (o.nonlinearity)
    c.push_back({"nonlinearity", "nonlinearity", "sensor nonlinearity (power law)",
                 {param("gamma", "", 1, 0.2, 5, 1e-4, {0.8, 1, 1.2})}, 0});
  if (o.qe_shift)
    c.push_back({"qe_shift", "qe_shift", "sensor QE wavelength shift",
                 {param("delta_nm", "nm", 0, -40, 40, 0.02, {-10, -4, 0, 4, 10})}, 0});
  if (o.nir_leak)
    c.push_back({"nir_leak", "nir_leak", "near-infrared leak through the IR-cut filter",
                 {param("transmittance", "", 0, 0, 1, 1e-5, {0, 0.01, 0.05, 0.2})}, 0});
  return c;
}

CameraCause camera_cause(const CandidateSpec& c) {
  if (c.name == "channel_gain") return CameraCause::kGain;
  if (c.name == "crosstalk") return CameraCause::kCrosstalk;
  if (c.name == "offset") return CameraCause::kOffset;
  if (c.name == "nonlinearity") return CameraCause::kNonlinearity;
  if (c.name == "qe_shift") return CameraCause::kQeShift;
  if (c.name == "nir_leak") return CameraCause::kNirLeak;
  throw std::logic_error("not a camera candidate: " + c.id);
}

void gaussian_blur(std::vector<double>& v, double step, double fwhm) {
  double sigma = fwhm / (2.0 * std::sqrt(2.0 * std::log(2.0))) / step;  // in samples
  if (!(sigma > 0.05)) return;
  int half = static_cast<int>(std::ceil(4 * sigma));
  std::vector<double> k(2 * half + 1);
  for (int i = -half; i <= half; ++i) k[i + half] = std::exp(-0.5 * (i / sigma) * (i / sigma));
  int n = static_cast<int>(v.size());
  std::vector<double> out(n);
  for (int i = 0; i < n; ++i) {
    double s = 0, w = 0;
    for (int j = std::max(0, i - half); j <= std::min(n - 1, i + half); ++j) {
      s += k[j - i + half] * v[j];
      w += k[j - i + half];
    }
    out[i] = s / w;
  }
  v.swap(out);
}

void shift_samples(std::vector<double>& v, double step, double delta) {
  if (delta == 0 || v.empty()) return;
  // Cubic (Catmull-Rom) interpolation: a linear one would also blur sharp features such as the
  // long-pass edge by up to half a grid step, which the fit then "explains" with other causes.
  const int n = static_cast<int>(v.size());
  auto at = [&](int i) { return v[std::clamp(i, 0, n - 1)]; };
  std::vector<double> out(n);
  const double d = delta / step;
  for (int i = 0; i < n; ++i) {
    double x = i - d;
    if (x <= 0) { out[i] = v[0]; continue; }
    if (x >= n - 1) { out[i] = v[n - 1]; continue; }
    int a = static_cast<int>(x);
    double t = x - a, p0 = at(a - 1), p1 = at(a), p2 = at(a + 1), p3 = at(a + 2);
    out[i] = p1 + 0.5 * t * (p2 - p0 + t * (2 * p0 - 5 * p1 + 4 * p2 - p3 + t * (3 * (p1 - p2) + p3 - p0)));
  }
  v.swap(out);
}

}  // namespace ofl
