#include "renderer/diagnose/problem/model_extensions.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "renderer/core/errors/error.h"

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

namespace {

// A cause free enough to follow almost any smooth residual (a band of free centre and width, a
// responsivity curve) is named only when what it explains held out is at least as large as the
// noise floor: smaller systematic residuals are what "fits at the noise floor" allows for.
constexpr double kFlexibleMinEffect = 1.0;
// Largest plausible detector-side offset, as a fraction of the spectrum's recorded peak.
constexpr double kStrayMaxOfPeak = 0.2;

CandidateSpec::Plausible plausible(std::string q, double lo, double hi, std::string why) {
  return {std::move(q), lo, hi, std::move(why)};
}

// Per-fluorophore shape causes of fluorophore f (those of an extra need the extra in the model).
void add_fluorophore_shapes(const SpectraCandidateOptions& o, const FluorophoreInfo& f, std::vector<CandidateSpec>& c) {
  std::string req = f.baseline ? "" : "extra_fluorophore:" + f.name;
  if (o.fluorophore_shape) {
    CandidateSpec s{"emission_shift:" + f.name, "emission_shift", "emission of " + f.name + " shifted",
                    {param("delta_nm", "nm", 0, -15, 15, 0.02, {-6, -2, 0, 2, 6})}, 0};
    s.requires_id = req;
    c.push_back(s);
    CandidateSpec w{"emission_width:" + f.name, "emission_width", "emission of " + f.name + " broader than the library's",
                    {param("fwhm_nm", "nm", 0, 0, 40, 0.05, {0, 5, 12, 25})}, 0};
    w.requires_id = req;
    c.push_back(w);
  }
  // Porphyrins and chlorins emit a vibronic second band (Q(0,1)) 50-70 nm beyond the main one;
  // flavins, NADH and the structural proteins do not, so only they get the candidate.
  bool has_second_band = f.name.find("porphyrin") != std::string::npos || f.name.find("chlorophyll") != std::string::npos;
  if (o.second_band && has_second_band) {
    double p0 = f.peak_nm;
    CandidateSpec b{"second_band:" + f.name, "second_band", "a second emission band of " + f.name,
                    {param("center_nm", "nm", p0 + 60, p0 + 25, p0 + 100, 0.05, {p0 + 35, p0 + 55, p0 + 75, p0 + 95}),
                     param("fwhm_nm", "nm", 25, 10, 50, 0.05, {15, 30}),
                     param("ratio", "of the main band's energy", 0.2, 0, 1.5, 1e-3, {0.1, 0.4})},
                    0};
    b.requires_id = req;
    c.push_back(b);
  }
}

}  // namespace

std::vector<double> response_knots(const SpectraRange& r) {
  int n = std::max(2, static_cast<int>(std::lround((r.max_nm - r.min_nm) / 40.0)) + 1);
  std::vector<double> k(n);
  for (int i = 0; i < n; ++i) k[i] = r.min_nm + (r.max_nm - r.min_nm) * i / (n - 1);
  return k;
}

std::vector<CandidateSpec> spectra_candidates(const SpectraCandidateOptions& o, const std::vector<FluorophoreInfo>& fl,
                                              const SpectraRange& range) {
  std::vector<CandidateSpec> c;
  if (o.blood) {
    // Starting grid spans optical densities at 577 nm from 0 to about 1.5 (oxy, 55000 cm^-1/M).
    std::vector<double> s = {0, 2, 8, 25};
    c.push_back({"blood_absorption", "blood_absorption", "blood absorption (oxy/deoxy hemoglobin, Beer-Lambert)",
                 {param("oxy_uM_cm", "umol/L*cm", 0, 0, 300, 0.05, s), param("deoxy_uM_cm", "umol/L*cm", 0, 0, 300, 0.05, s)},
                 0});
  }
  if (o.extra_fluorophore)
    for (auto& f : fl)
      if (!f.baseline) {
        CandidateSpec e{"extra_fluorophore:" + f.name, "extra_fluorophore", "an extra fluorophore (" + f.name + ")", {}, 1};
        e.plausible.push_back(plausible("mean_fraction", 0.005, 1, "a share below 0.5 % of the signal is not a finding"));
        c.push_back(e);
      }
  if (o.shift) {
    CandidateSpec s{"wavelength_shift", "wavelength_shift", "wavelength calibration shift (whole instrument axis)",
                    {param("delta_nm", "nm", 0, -10, 10, 0.02, {-3, -1, 0, 1, 3})}, 0};
    s.instrument = true;
    s.plausible.push_back(plausible("delta_nm", -5, 5, "a spectroradiometer's wavelength accuracy is about +-2 nm"));
    c.push_back(s);
  }
  if (o.emission_shift)
    c.push_back({"emission_shift", "emission_shift", "every fluorophore's emission shifted (fluorescence only)",
                 {param("delta_nm", "nm", 0, -10, 10, 0.02, {-3, -1, 0, 1, 3})}, 0});
  if (o.bandwidth) {
    CandidateSpec b{"bandwidth", "bandwidth", "spectral bandwidth (extra Gaussian blur)",
                    {param("fwhm_nm", "nm", 0, 0, 40, 0.05, {0, 3, 6, 10, 16})}, 0};
    b.instrument = true;
    b.plausible.push_back(plausible("fwhm_nm", 0, 15, "beyond 15 nm the instrument would not resolve the hemoglobin bands"));
    c.push_back(b);
  }
  if (o.broadening)
    c.push_back({"emission_broadening", "emission_broadening", "every fluorophore's emission broader than the library's (one width)",
                 {param("fwhm_nm", "nm", 0, 0, 60, 0.05, {0, 5, 10, 20, 30})}, 0});
  if (o.fluorophore_shape || o.second_band)
    for (auto& f : fl) add_fluorophore_shapes(o, f, c);
  if (o.fluorophore_shape) {
    std::vector<ParamSpec> ps;
    for (auto& f : fl)
      if (f.baseline) ps.push_back(param("fwhm_nm:" + f.name, "nm", 0, 0, 40, 0.05, {0, 10, 25}));
    if (ps.size() > 1) {
      // The start grid is the product over parameters: keep it small.
      for (auto& q : ps) q.starts = {0, 20};
      c.push_back({"emission_width:each", "emission_width_each", "each baseline fluorophore's emission broadened by its own width", ps, 0});
    }
  }
  if (o.stray) {
    // A flat offset on the detector side, its level fitted per spectrum (a dark level does not
    // scale with the tissue's signal; stray light scales with everything the array sees). Judged
    // against the instrument's level, the spectrum's recorded peak, not the tissue's mean signal:
    // a dim autofluorescence spectrum may sit on a dark level of a sixth of its mean.
    CandidateSpec s{"stray_light", "stray_light", "a flat offset under every spectrum (detector side: dark level or stray light)", {}, 1};
    s.instrument = true;
    s.plausible.push_back(plausible("fraction_of_peak", 0, kStrayMaxOfPeak,
                                    "a working spectroradiometer's dark level and stray light stay well below a fifth of the "
                                    "recorded peak; a flat column that large more likely stands in for a broad emission the "
                                    "model lacks"));
    c.push_back(s);
  }
  if (o.leak) {
    CandidateSpec l{"longpass_leak", "longpass_leak", "excitation leak through the long-pass filter", {}, o.leak_passband ? 2 : 1};
    l.instrument = true;
    c.push_back(l);
  }
  if (o.edge) {
    CandidateSpec e{"longpass_edge", "longpass_edge", "long-pass filter edge shifted",
                    {param("shift_nm", "nm", 0, -20, 20, 0.02, {-6, -3, 0, 3, 6})}, 0};
    e.instrument = true;
    c.push_back(e);
  }
  if (o.unknown_band) {
    std::vector<double> centres;
    for (double x = range.min_nm + 15; x <= range.max_nm - 10; x += 15) centres.push_back(x);
    CandidateSpec u{"unknown_band", "unknown_band", "an emission band in no library spectrum",
                    {param("center_nm", "nm", 0.5 * (range.min_nm + range.max_nm), range.min_nm, range.max_nm, 0.05, centres),
                     param("fwhm_nm", "nm", 40, 8, 150, 0.05, {25, 50, 90}),
                     param("asymmetry", "red/blue half-width ratio", 1, 0.4, 2.5, 1e-3)},
                    1};
    u.min_effect_to_noise = kFlexibleMinEffect;
    c.push_back(u);
  }
  if (o.instrument_response) {
    std::vector<ParamSpec> ps;
    for (double k : response_knots(range)) {
      char b[32];
      std::snprintf(b, sizeof b, "log_gain_%.0f", k);
      ps.push_back(param(b, "ln(responsivity ratio)", 0, -0.7, 0.7, 1e-4));
    }
    CandidateSpec r{"instrument_response", "instrument_response", "the instrument's spectral responsivity is off (smooth factor)", ps, 0};
    r.instrument = true;
    r.min_effect_to_noise = kFlexibleMinEffect;
    c.push_back(r);
  }
  apply_plausible(c, o.plausible);
  for (auto& r : o.plausible) {
    bool any = false;
    for (auto& cs : c) any = any || cs.id == r.candidate || cs.name == r.candidate;
    if (!any) throw InputError("model", "/plausible/" + r.candidate, "no candidate cause of that name or id");
  }
  return c;
}

void apply_plausible(std::vector<CandidateSpec>& c, const std::vector<SpectraCandidateOptions::Range>& ranges) {
  for (auto& r : ranges)
    for (auto& cs : c)
      if (cs.id == r.candidate || cs.name == r.candidate) {
        bool found = false;
        for (auto& q : cs.plausible)
          if (q.quantity == r.quantity) { q.lo = r.lo; q.hi = r.hi; q.why = "set in the model"; found = true; }
        if (!found) cs.plausible.push_back(plausible(r.quantity, r.lo, r.hi, "set in the model"));
      }
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
  if (c.id == "emission_shift") return SpectraCause::kEmissionShift;
  if (c.name == "emission_shift") return SpectraCause::kFluorShift;
  if (c.name == "emission_width") return SpectraCause::kFluorWidth;
  if (c.name == "emission_width_each") return SpectraCause::kFluorWidthEach;
  if (c.name == "second_band") return SpectraCause::kSecondBand;
  if (c.name == "unknown_band") return SpectraCause::kUnknownBand;
  if (c.name == "instrument_response") return SpectraCause::kResponse;
  if (c.name == "layered_tissue") return SpectraCause::kLayered;
  throw std::logic_error("not a spectra candidate: " + c.id);
}

std::string extra_fluorophore_name(const CandidateSpec& c) {
  auto p = c.id.find(':');
  return p == std::string::npos ? std::string() : c.id.substr(p + 1);
}

std::string cause_fluorophore(const CandidateSpec& c) {
  if (c.name == "emission_width_each") return "";
  return extra_fluorophore_name(c);
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
  for (auto& x : c) x.instrument = true;  // every camera cause is a property of the camera
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

}  // namespace ofl
