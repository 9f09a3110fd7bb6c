// Synthetic spectroradiometer data made WITHOUT diagnose's forward model, for the tests and the
// benchmark (tests/test_diagnose_independent.cpp, benchmarks/diagnose_independent.cpp).
// What differs from tests/support/synthetic.h (which reuses SpectraProblem) on purpose:
// - wavelength handling: generated on a 0.5 nm grid, sampled every 3 nm from 381.5 nm (the model
//   works on its own 2 nm grid);
// - fluorophores: the library's raw EEM tables interpolated bilinearly here, excitation counted
//   explicitly in photons (E * lambda / hc) and emission converted back to energy (hc / lambda);
// - the long-pass filter is a logistic edge in optical density (the model uses its own filter
//   shape with the same nominal edge, width and OD: a small, realistic instrument mismatch);
// - effects are applied where they physically act: an emission shift moves the EEM's emission
//   axis, an axis shift resamples what the instrument records, an offset is added to the record.
// The LED and white-target leak spectra are the shipped measured files (data, not model).
#pragma once
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "renderer/core/files/asset_path.h"
#include "renderer/diagnose/spectra/forward_model.h"
#include "tests/support/synthetic.h"
#include "renderer/spectral/chromophores/eem.h"
#include "renderer/spectral/spectra/spectrum.h"

namespace ofl::indep {

struct Options {
  uint64_t seed = 1;
  // "" (null data), "emission_shift" (every fluorophore), "emission_shift:FAD", "wavelength_shift"
  // (instrument axis), "offset" (flat, fraction of the mean), "offset_peak" (flat, detector side: a
  // fraction of each spectrum's recorded peak), "excitation_leak" (LED light through
  // the long-pass at an effective OD), "unknown_fluorophore" (a band in no library spectrum),
  // "subset_chlorophyll" (chlorophyll-a in one subject only).
  std::string effect;
  double magnitude = NAN;  // the effect's size (NaN: random in its range)
  int subjects = 4;
  int locations = 2;
  double noise_relative = 0.01, noise_floor = 0.002, jitter = 0.05;
  double white_leak = 1.0;  // scale of the white-target leak every spectrum carries (1: about 1 % of the signal)
  // Shape of the unknown fluorophore's band: "wavenumber" (Gaussian in wavenumber, 1500 cm^-1
  // FWHM), "wavelength" (Gaussian in wavelength, 50 nm FWHM), "skewed" (two half Gaussians in
  // wavelength, 18 nm to the blue and 36 nm to the red of the peak).
  std::string band_shape = "wavenumber";
  // The instrument slightly other than the model describes it (null data otherwise; no tissue cause
  // may be claimed): "" (as described), "edge" (the long-pass edge 1.5 nm to the red of the stated
  // 475 nm), "response" (the recorded spectral responsivity tilted by -6 % at 470 nm to +6 % at 730 nm),
  // "edge_width" (the long-pass rises over 7.5 nm, not 5), "blur" (the instrument blurs by 3 nm FWHM
  // more than stated).
  std::string instrument_error;
  // What the fitting model is told of the leak: "measured" (the white-target records), "none" (no
  // leak column: the longpass_leak candidate is computed from the LED spectra and the long-pass).
  // Data made for a "none" model should use white_leak = 0.
  std::string model_leak = "measured";
};

struct Data {
  SpectraSet set;
  SpectraModel model;
  std::string effect;
  std::map<std::string, double> truth;  // "delta_nm", "fraction", "effective_od", "peak_nm", "mean_fraction"
  std::string carrier;                  // subset carrying the effect ("subject=S2")
};

namespace detail {

inline double lerp_table(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (x.empty() || at < x.front() || at > x.back()) return 0.0;
  size_t k = std::upper_bound(x.begin(), x.end(), at) - x.begin();
  if (k == 0) return y.front();
  if (k >= x.size()) return y.back();
  double t = (at - x[k - 1]) / (x[k] - x[k - 1]);
  return y[k - 1] * (1 - t) + y[k] * t;
}

// Bilinear lookup in a raw EEM table (zero outside it and at or below the diagonal).
inline double eem_at(const Eem& e, double em, double ex) {
  if (em <= ex || em < e.em_nm.front() || em > e.em_nm.back() || ex < e.ex_nm.front() || ex > e.ex_nm.back()) return 0.0;
  size_t r = std::min<size_t>(std::upper_bound(e.em_nm.begin(), e.em_nm.end(), em) - e.em_nm.begin(), e.em_nm.size() - 1);
  size_t c = std::min<size_t>(std::upper_bound(e.ex_nm.begin(), e.ex_nm.end(), ex) - e.ex_nm.begin(), e.ex_nm.size() - 1);
  if (r == 0) r = 1;
  if (c == 0) c = 1;
  double tr = (em - e.em_nm[r - 1]) / (e.em_nm[r] - e.em_nm[r - 1]);
  double tc = (ex - e.ex_nm[c - 1]) / (e.ex_nm[c] - e.ex_nm[c - 1]);
  return (1 - tr) * ((1 - tc) * e.at(r - 1, c - 1) + tc * e.at(r - 1, c)) + tr * ((1 - tc) * e.at(r, c - 1) + tc * e.at(r, c));
}

struct Table {
  std::vector<double> nm, v;
};
inline Table read_table(const std::string& rel) {
  SpectrumCsvOptions o;
  auto t = read_spectrum_csv(asset_root() / rel, o);
  return {t.nm, t.value};
}

}  // namespace detail

// The fitting model these data are meant for (what a user would write): baseline collagen, NADH
// and FAD; extra candidates chlorophyll-a, keratin and bacterial porphyrin; the shipped LED and
// leak spectra; the nominal 475 nm long-pass.
inline SpectraModel independent_model() {
  // The instrument as the user describes it is the one of the other synthetic tests (shipped LED
  // and leak spectra, nominal long-pass); only the data generation below is independent.
  SpectraModel m = synthetic_spectra_model(SyntheticSpectraOptions{});
  m.fluorophores = {"collagen", "NADH", "FAD"};
  m.fit_min_nm = 470;
  m.fit_max_nm = 745;
  m.grid_step_nm = 0.5;  // half the long-pass edge's scale (5 nm / 4.39) or less: docs/diagnose.md "Model grid"
  m.candidates.extra_from = {"chlorophyll_a", "keratin", "porphyrin_bacterial"};
  return m;
}

inline Data make_independent(const Options& o) {
  using namespace detail;
  std::mt19937_64 rng(o.seed * 7919 + 17);
  auto U = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  auto sign = [&]() { return U(0, 1) < 0.5 ? -1.0 : 1.0; };
  std::normal_distribution<double> normal(0, 1);

  Data d;
  d.model = independent_model();
  if (o.model_leak == "none")
    d.model.leak = LeakSource::kNone;
  else if (o.model_leak != "measured")
    throw std::invalid_argument("independent generator: unknown model_leak " + o.model_leak);
  d.effect = o.effect;
  d.set.index_file = "independent";

  const char* eem_files[] = {"fluorophores/collagen1_Webfluor_EEM.csv", "fluorophores/NADH_Webfluor_EEM.csv",
                             "fluorophores/FAD_Webfluor_EEM.csv", "fluorophores/chlorophyllA-7_isetfluorescence_EEM.csv"};
  std::vector<Eem> eems;
  for (auto* f : eem_files) eems.push_back(read_eem_csv(asset_root() / f));
  const int kChl = 3;
  const int leds[] = {405, 415, 450};
  const int currents[] = {980, 910, 870};

  // The hidden effect's size.
  double m = o.magnitude;
  std::vector<double> shift(4, 0.0);
  double axis = 0, offset = 0, offset_peak = 0, leak_od = 99, band_peak = 0, band_share = 0, chl_share = 0;
  double leak_log_sum = 0;
  int leak_count = 0;
  int carrier_subject = -1;
  if (o.effect == "emission_shift") {
    if (std::isnan(m)) m = sign() * U(1, 3);
    for (int k = 0; k < 3; ++k) shift[k] = m;
    d.truth["delta_nm"] = m;
  } else if (o.effect == "emission_shift:FAD") {
    if (std::isnan(m)) m = sign() * U(2, 5);
    shift[2] = m;
    d.truth["delta_nm"] = m;
  } else if (o.effect == "wavelength_shift") {
    if (std::isnan(m)) m = sign() * U(1, 3);
    axis = m;
    d.truth["delta_nm"] = m;
  } else if (o.effect == "offset") {
    if (std::isnan(m)) m = U(0.02, 0.06);
    offset = m;
    d.truth["fraction"] = m;
  } else if (o.effect == "offset_peak") {
    if (std::isnan(m)) m = U(0.01, 0.08);
    offset_peak = m;
    d.truth["fraction_of_peak"] = m;
  } else if (o.effect == "excitation_leak") {
    // Size: the leaked light's mean over the fit range as a fraction of the signal; the truth is
    // the effective OD (mean over spectra of -log10 of leaked / LED radiance), as diagnose reports it.
    if (std::isnan(m)) m = U(0.01, 0.04);
    leak_od = m;
  } else if (o.effect == "unknown_fluorophore") {
    if (std::isnan(m)) m = U(570, 690);
    band_peak = m;
    band_share = U(0.1, 0.2);
  } else if (o.effect == "subset_chlorophyll") {
    if (std::isnan(m)) m = U(0.2, 0.35);
    chl_share = m;
    carrier_subject = static_cast<int>(U(0, o.subjects - 1e-9));
    d.carrier = "subject=S" + std::to_string(carrier_subject + 1);
    d.truth["mean_fraction"] = m;
  } else if (!o.effect.empty()) {
    throw std::invalid_argument("independent generator: unknown effect " + o.effect);
  }
  if (!o.instrument_error.empty() && o.instrument_error != "edge" && o.instrument_error != "response" &&
      o.instrument_error != "edge_width" && o.instrument_error != "blur")
    throw std::invalid_argument("independent generator: unknown instrument error " + o.instrument_error);

  // 0.5 nm generation grid.
  std::vector<double> g;
  for (double w = 300; w <= 800; w += 0.5) g.push_back(w);
  const size_t N = g.size();
  auto in_fit = [&](double w) { return w >= 480 && w <= 740; };
  // Logistic long-pass in transmittance: 10-90 % rise over width_nm.
  auto longpass = [&](double w) {
    double tmin = 1e-6, peak = 0.95, s = (o.instrument_error == "edge_width" ? 7.5 : 5.0) / 4.394;
    double edge = 475 + (o.instrument_error == "edge" ? 1.5 : 0.0);
    return tmin + (peak - tmin) / (1 + std::exp(-(w - edge) / s));
  };
  // A band in no library spectrum, in one of three shapes none of which is the model's log-normal
  // (the Gaussian in wavenumber is its symmetric limit).
  auto band = [&](double w) {
    if (o.band_shape == "wavelength") {
      double s = 50 / 2.3548;
      return std::exp(-0.5 * (w - band_peak) * (w - band_peak) / (s * s));
    }
    if (o.band_shape == "skewed") {
      double s = (w < band_peak ? 18 : 36) / 2.3548;
      return std::exp(-0.5 * (w - band_peak) * (w - band_peak) / (s * s));
    }
    if (o.band_shape != "wavenumber") throw std::invalid_argument("independent generator: unknown band shape " + o.band_shape);
    double k = 1e7 / w, k0 = 1e7 / band_peak, s = 1500 / 2.3548;
    return std::exp(-0.5 * (k - k0) * (k - k0) / (s * s)) / (w * w);  // per nm (Jacobian dk/dl)
  };

  for (int li = 0; li < 3; ++li) {
    const std::string L = "lights/oe_tongue_lip/ExcitationLights/";
    Table led = read_table(L + "spd-2024-03-07-verif-" + std::to_string(leds[li]) + "nm450SPF-" + std::to_string(currents[li]) + "mA.csv");
    Table wleak = read_table(L + "spd-2024-03-17-NoiseCheck-" + std::to_string(leds[li]) + "nm_" + std::to_string(currents[li]) + "mA.csv");
    std::vector<double> photons(N), e(N);
    for (size_t i = 0; i < N; ++i) {
      e[i] = std::max(0.0, lerp_table(led.nm, led.v, g[i]));
      photons[i] = e[i] * g[i] * 1e-9 / (6.62607015e-34 * 2.99792458e8);  // photons s^-1 ... per nm
    }
    // Emission radiance of each fluorophore (energy units), normalised to unit mean in the fit range.
    std::vector<std::vector<double>> emis(4, std::vector<double>(N, 0.0));
    for (int k = 0; k < 4; ++k) {
      double mean = 0;
      int cnt = 0;
      for (size_t i = 0; i < N; ++i) {
        double p = 0;
        for (size_t j = 0; j < N; ++j)
          if (photons[j] > 0) p += photons[j] * eem_at(eems[k], g[i] - shift[k], g[j]) * 0.5;
        emis[k][i] = p * 6.62607015e-34 * 2.99792458e8 / (g[i] * 1e-9);
        if (in_fit(g[i])) { mean += emis[k][i]; ++cnt; }
      }
      for (double& v : emis[k]) v /= std::max(mean / cnt, 1e-300);
    }
    std::vector<double> bandv(N, 0.0);
    if (band_share > 0) {
      double mean = 0;
      int cnt = 0;
      for (size_t i = 0; i < N; ++i) {
        bandv[i] = band(g[i]);
        if (in_fit(g[i])) { mean += bandv[i]; ++cnt; }
      }
      for (double& v : bandv) v /= mean / cnt;
      // The truth is the band's peak in energy per nm (a little shorter than its wavenumber centre).
      d.truth["peak_nm"] = g[std::max_element(bandv.begin(), bandv.end()) - bandv.begin()];
    }
    for (int s = 0; s < o.subjects; ++s)
      for (const char* site : {"lip", "tongue"}) {
        // Composition of this subject and site; each location jitters it.
        double base[3] = {U(0.2, 1.0), U(0.2, 1.0), U(0.2, 1.0)};
        double leak_amp = U(0.5, 1.5);
        for (int loc = 0; loc < o.locations; ++loc) {
          std::vector<double> tissue(N, 0.0);
          double sum = 0;
          for (int k = 0; k < 3; ++k) {
            double c = base[k] * std::exp(o.jitter * normal(rng));
            sum += c;
            for (size_t i = 0; i < N; ++i) tissue[i] += c * emis[k][i];
          }
          // Shares of the signal: chlorophyll and the unknown band added at their share.
          if (chl_share > 0 && s == carrier_subject)
            for (size_t i = 0; i < N; ++i) tissue[i] += sum * chl_share / (1 - chl_share) * emis[kChl][i];
          if (band_share > 0)
            for (size_t i = 0; i < N; ++i) tissue[i] += sum * band_share / (1 - band_share) * bandv[i];
          // Through the long-pass, plus the white-target leak (baseline) and an excitation leak.
          std::vector<double> rec(N);
          double sig_mean = 0;
          int cnt = 0;
          for (size_t i = 0; i < N; ++i) {
            rec[i] = tissue[i] * longpass(g[i]);
            if (in_fit(g[i])) { sig_mean += rec[i]; ++cnt; }
          }
          sig_mean /= cnt;
          double leak_scale = 0;
          {
            double lm = 0;
            int lc = 0;
            for (size_t i = 0; i < N; ++i)
              if (in_fit(g[i])) { lm += std::max(0.0, lerp_table(wleak.nm, wleak.v, g[i])); ++lc; }
            lm /= lc;
            leak_scale = lm > 0 ? 0.01 * o.white_leak * sig_mean * leak_amp / lm : 0;  // the baseline leak: ~1 % of the signal
          }
          double emax = *std::max_element(e.begin(), e.end());
          double leak_amp_ex = 0;
          if (leak_od < 50) {
            double lm = 0;
            int lc = 0;
            for (size_t i = 0; i < N; ++i)
              if (in_fit(g[i]) && e[i] > 1e-3 * emax) lm += e[i] * (1 - longpass(g[i]) / 0.95);
            for (size_t i = 0; i < N; ++i) lc += in_fit(g[i]) ? 1 : 0;
            lm /= lc;
            leak_amp_ex = lm > 0 ? leak_od * sig_mean / lm : 0;
            if (leak_amp_ex > 0) {
              leak_log_sum += -std::log10(leak_amp_ex);
              ++leak_count;
            }
          }
          for (size_t i = 0; i < N; ++i) {
            rec[i] += leak_scale * std::max(0.0, lerp_table(wleak.nm, wleak.v, g[i]));
            if (leak_amp_ex > 0 && e[i] > 1e-3 * emax) rec[i] += e[i] * leak_amp_ex * (1 - longpass(g[i]) / 0.95);
          }
          for (size_t i = 0; i < N; ++i) rec[i] += offset * sig_mean;
          if (offset_peak > 0) {  // detector side: a fraction of what the spectrum records at its peak
            double peak = 0;
            for (size_t i = 0; i < N; ++i)
              if (in_fit(g[i])) peak = std::max(peak, rec[i]);
            for (size_t i = 0; i < N; ++i) rec[i] += offset_peak * peak;
          }
          if (o.instrument_error == "blur") {  // a Gaussian of 3 nm FWHM on the 0.5 nm grid
            const double sg = 3.0 / 2.3548;
            std::vector<double> b(N, 0.0);
            for (size_t i = 0; i < N; ++i) {
              double wsum = 0;
              for (int k = -12; k <= 12; ++k) {
                long j = static_cast<long>(i) + k;
                if (j < 0 || j >= static_cast<long>(N)) continue;
                double w = std::exp(-0.5 * (0.5 * k / sg) * (0.5 * k / sg));
                b[i] += w * rec[j];
                wsum += w;
              }
              b[i] /= wsum;
            }
            rec = b;
          }
          // The instrument records every 3 nm, its axis shifted by `axis`, with noise.
          MeasuredSpectrum ms;
          ms.conditions = {{"subject", "S" + std::to_string(s + 1)}, {"site", site}, {"light_nm", std::to_string(leds[li])},
                           {"location", "R0" + std::to_string(loc + 1)}};
          ms.label = "S" + std::to_string(s + 1) + "-" + site + "-" + std::to_string(leds[li]) + "-R0" + std::to_string(loc + 1);
          ms.file = ms.label + ".csv";
          ms.index_line = static_cast<int>(d.set.spectra.size()) + 2;
          for (double w = 381.5; w <= 779; w += 3) {
            double y = lerp_table(g, rec, w - axis);
            if (o.instrument_error == "response") y *= 1 + 0.06 * (w - 600) / 130;
            y += (o.noise_relative * std::sqrt(std::max(0.0, y) * sig_mean) + o.noise_floor * sig_mean) * normal(rng);
            ms.nm.push_back(w);
            ms.value.push_back(y);
          }
          d.set.spectra.push_back(std::move(ms));
        }
      }
  }
  if (leak_count) d.truth["effective_od"] = leak_log_sum / leak_count;
  return d;
}

}  // namespace ofl::indep
