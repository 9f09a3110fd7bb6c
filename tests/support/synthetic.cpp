#include "tests/support/synthetic.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "renderer/core/files/asset_path.h"
#include "renderer/core/files/csv.h"
#include "renderer/core/errors/error.h"
#include "renderer/diagnose/selection/global_fit.h"

namespace ofl {

namespace {

struct Rng {
  std::mt19937_64 g;
  explicit Rng(uint64_t s) : g(s * 0x9E3779B97F4A7C15ull + 12345) {}
  double uniform(double a, double b) { return a + (b - a) * std::uniform_real_distribution<double>(0, 1)(g); }
  double normal() { return std::normal_distribution<double>(0, 1)(g); }
  double sign() { return uniform(0, 1) < 0.5 ? -1 : 1; }
  int index(int n) { return std::min(n - 1, static_cast<int>(uniform(0, n))); }
};

Spectrum csv(const std::string& rel, const std::string& column = "") {
  SpectrumCsvOptions o;
  o.column = column;
  return table_spectrum(read_spectrum_csv(asset_path(rel), o), rel);
}

int find_candidate(const DiagnoseProblem& p, const std::string& id) {
  for (size_t k = 0; k < p.candidates().size(); ++k)
    if (p.candidates()[k].id == id) return static_cast<int>(k);
  throw std::logic_error("synthetic: no candidate " + id);
}

}  // namespace

SpectraModel synthetic_spectra_model(const SyntheticSpectraOptions& o) {
  SpectraModel m;
  m.fluorophores = {"collagen", "NADH", "FAD", "keratin", "protoporphyrin"};
  const std::string L = "lights/oe_tongue_lip/ExcitationLights/";
  struct { int nm, mA; } leds[] = {{405, 980}, {415, 910}, {450, 870}};
  for (auto& l : leds) {
    LightEntry e;
    e.name = std::to_string(l.nm) + " nm";
    e.when["light_nm"] = std::to_string(l.nm);
    e.spectrum = csv(L + "spd-2024-03-07-verif-" + std::to_string(l.nm) + "nm450SPF-" + std::to_string(l.mA) + "mA.csv");
    e.leak = csv(L + "spd-2024-03-17-NoiseCheck-" + std::to_string(l.nm) + "nm_" + std::to_string(l.mA) + "mA.csv");
    m.lights.push_back(e);
  }
  OpticalFilter lp;
  lp.kind = OpticalFilter::Kind::kLongpass;
  lp.edge_nm = 475;
  lp.width_nm = 5;
  lp.od = 6;
  lp.peak = 0.95;
  m.emission_filter = lp;
  m.leak = LeakSource::kMeasured;
  m.fit_min_nm = o.fit_min_nm;
  m.fit_max_nm = o.fit_max_nm;
  m.grid_step_nm = o.model_step_nm > 0 ? o.model_step_nm : o.step_nm;
  m.candidates.extra_from = {"chlorophyll_a", "elastin", "teeth"};
  return m;
}

std::vector<std::string> synthetic_spectra_replicates() { return {"subject", "site", "light_nm"}; }

SyntheticSpectra make_synthetic_spectra(const SyntheticSpectraOptions& o) {
  Rng rng(o.seed);
  SyntheticSpectra out;
  out.model = synthetic_spectra_model(o);
  SpectraSet tmpl;
  tmpl.index_file = "synthetic";
  std::vector<double> nm;
  for (double w = o.min_nm; w <= o.max_nm + 1e-9; w += o.step_nm) nm.push_back(w);
  for (int s = 0; s < o.subjects; ++s)
    for (auto& site : o.sites)
      for (auto& L : out.model.lights)
        for (int loc = 0; loc < o.locations; ++loc) {
          MeasuredSpectrum m;
          m.conditions = {{"subject", "S" + std::to_string(s + 1)},
                          {"site", site},
                          {"light_nm", L.when.at("light_nm")},
                          {"location", "R0" + std::to_string(loc + 1)}};
          m.label = "S" + std::to_string(s + 1) + "-" + site + "-" + L.when.at("light_nm") + "nm-R0" + std::to_string(loc + 1);
          m.file = m.label + ".csv";
          m.index_line = static_cast<int>(tmpl.spectra.size()) + 2;
          m.nm = nm;
          m.value.assign(nm.size(), 1.0);
          tmpl.spectra.push_back(m);
        }
  SpectraModel gen_model = out.model;
  gen_model.grid_step_nm = o.generation_step_nm > 0 ? o.generation_step_nm : o.step_nm;
  SpectraProblem p0(tmpl, gen_model);

  // The hidden effect and its parameters.
  ModelState truth;
  std::string extra;
  double stray = 0;
  if (!o.effect.empty()) {
    std::string id = o.effect;
    if (o.effect == "extra_fluorophore") {
      auto& from = out.model.candidates.extra_from;
      extra = o.extra_fluorophore.empty() ? from[rng.index(static_cast<int>(from.size()))] : o.extra_fluorophore;
      id = "extra_fluorophore:" + extra;
    }
    int c = find_candidate(p0, id);
    truth = with_cause(p0, truth, c);
    auto& th = truth.causes[0].theta;
    const std::string& n = p0.candidates()[c].name;
    if (n == "blood_absorption") {
      th = {rng.uniform(2, 12), rng.uniform(0.5, 5)};
      out.truth = {{"oxy_uM_cm", th[0]}, {"deoxy_uM_cm", th[1]}};
    } else if (n == "wavelength_shift") {
      th = {rng.sign() * rng.uniform(0.5, 2.5)};
      if (o.magnitude >= 0) th[0] = o.magnitude;
      out.truth = {{"delta_nm", th[0]}};
    } else if (n == "bandwidth") {
      th = {rng.uniform(6, 14)};
      if (o.magnitude >= 0) th[0] = o.magnitude;
      out.truth = {{"fwhm_nm", th[0]}};
    } else if (n == "emission_broadening") {
      th = {rng.uniform(8, 20)};
      if (o.magnitude >= 0) th[0] = o.magnitude;
      out.truth = {{"fwhm_nm", th[0]}};
    } else if (n == "stray_light") {
      // A flat offset, a fraction of each spectrum's mean signal (the cause fits its level per
      // spectrum and reports that fraction).
      stray = o.magnitude >= 0 ? o.magnitude : rng.uniform(0.02, 0.06);
      out.truth = {{"fraction", stray}};
    } else if (n == "longpass_edge") {
      th = {rng.sign() * rng.uniform(3, 8)};
      if (o.magnitude >= 0) th[0] = o.magnitude;
      out.truth = {{"shift_nm", th[0]}};
    }
    out.effect_id = id;
  }
  double leak_od = rng.uniform(4.5, 5.5);
  double extra_share = rng.uniform(0.08, 0.25);
  if (o.magnitude >= 0 && o.effect == "longpass_leak") leak_od = o.magnitude;
  if (o.magnitude >= 0 && o.effect == "extra_fluorophore") extra_share = o.magnitude;

  // Compositions: shares of the predicted signal per subject and site, jittered per location.
  std::map<std::string, std::vector<double>> base_share;
  SpectraSet data = tmpl;
  double extra_frac_sum = 0;
  int extra_frac_n = 0;
  for (int i = 0; i < p0.num_items(); ++i) {
    auto& cond = tmpl.spectra[i].conditions;
    std::string key = cond.at("subject") + "|" + cond.at("site");
    bool tongue = cond.at("site") == "tongue";
    if (!base_share.count(key))
      base_share[key] = {rng.uniform(0.2, 0.4), rng.uniform(0.05, 0.15), rng.uniform(0.2, 0.4), rng.uniform(0.05, 0.15),
                         tongue ? rng.uniform(0.02, 0.1) : rng.uniform(0.0, 0.02)};
    auto D = p0.design(truth, i);
    const auto& A = D.A;
    std::vector<double> share = base_share[key];
    for (double& s : share) s *= std::exp(o.location_jitter * rng.normal());
    double total = 0;
    for (double s : share) total += s;
    double fluo_total = extra.empty() ? 1.0 : 1.0 - extra_share;
    double S = 5e-4 * std::exp(rng.uniform(std::log(0.3), std::log(3.0)));  // radiance level (LED current)
    Eigen::VectorXd c = Eigen::VectorXd::Zero(A.cols());
    auto mean_col = [&](Eigen::Index j) { return std::max(A.col(j).mean(), 1e-300); };
    for (Eigen::Index j = 0; j < A.cols(); ++j) {
      const std::string& name = D.names[j];
      auto it = std::find(out.model.fluorophores.begin(), out.model.fluorophores.end(), name);
      if (it != out.model.fluorophores.end())
        c[j] = share[it - out.model.fluorophores.begin()] / total * fluo_total * S / mean_col(j);
      else if (name == extra)
        c[j] = extra_share * S / mean_col(j);
      else if (name == "leak")
        c[j] = rng.uniform(0.2, 0.5);  // white-target leak times tissue reflectance
      else if (name == "longpass_leak")
        c[j] = std::pow(10.0, -leak_od);
    }
    Eigen::VectorXd y = A * c;
    if (stray > 0) y.array() += stray * y.mean();
    double ybar = y.mean();
    if (!extra.empty())
      for (Eigen::Index j = 0; j < A.cols(); ++j)
        if (D.names[j] == extra) { extra_frac_sum += (A.col(j) * c[j]).mean() / ybar; ++extra_frac_n; }
    // The template's fit range defines the design rows; the file keeps the full range with the
    // model evaluated everywhere (outside the fit range it is never looked at).
    auto& m = data.spectra[i];
    std::vector<double> fit_y(y.data(), y.data() + y.size());
    size_t k = 0;
    for (size_t r = 0; r < m.nm.size(); ++r) {
      double v;
      if (m.nm[r] >= out.model.fit_min_nm && m.nm[r] <= out.model.fit_max_nm)
        v = fit_y[k++];
      else
        v = ybar * 0.01;  // outside the fit range: a placeholder level, never fitted
      double sigma = o.noise_relative * std::sqrt(std::max(v, 0.0) * ybar) + o.noise_floor * ybar;
      m.value[r] = v + sigma * rng.normal();
    }
  }
  if (!extra.empty()) out.truth = {{"mean_fraction", extra_frac_sum / std::max(1, extra_frac_n)}};
  if (o.effect == "longpass_leak") out.truth = {{"effective_od", leak_od}};
  out.data = std::move(data);
  return out;
}

double stated_tolerance(const std::string& n, double truth) {
  double a = std::fabs(truth);
  if (n == "blood_absorption") return std::max(0.25 * a, 1.0);
  if (n == "extra_fluorophore") return 0.3 * a;
  if (n == "wavelength_shift") return 0.25;
  if (n == "bandwidth" || n == "emission_broadening" || n == "stray_light") return 0.2 * a;
  if (n == "longpass_leak") return 0.15;
  if (n == "longpass_edge") return 0.5;
  if (n == "channel_gain") return 0.02;
  if (n == "crosstalk") return 0.015;
  if (n == "offset") return 5;
  if (n == "nonlinearity") return 0.015;
  if (n == "qe_shift") return 1.0;
  if (n == "nir_leak") return 0.25 * a;
  return 0;
}

CameraModel example_camera_model() {
  CameraModel m;
  const std::string s = "measurements/camera_example/sensor/";
  m.qe[0] = csv(s + "MT9V024_RGB.csv", "r");
  m.qe[1] = csv(s + "MT9V024_RGB.csv", "g");
  m.qe[2] = csv(s + "MT9V024_RGB.csv", "b");
  m.filters.push_back(csv(s + "ircf_public.csv"));
  m.grid_step_nm = 4;
  return m;
}

SyntheticCamera make_synthetic_camera(const SyntheticCameraOptions& o) {
  Rng rng(o.seed);
  SyntheticCamera out;
  out.model = example_camera_model();
  auto refl_file = asset_path("measurements/camera_example/source/macbethChart.csv");
  CsvNumeric mcc = read_numeric_csv(refl_file);
  const double kelvins[2] = {3000, 5000};
  CameraPatchSet tmpl;
  tmpl.file = "synthetic";
  for (int il = 0; il < 2; ++il) {
    Spectrum bb = blackbody_spectrum(kelvins[il]);
    for (size_t col = 1; col < mcc.header.size(); ++col) {
      // Header "colNN_mccMM_name": MM is the standard patch number, row-major over 4 x 6.
      const std::string& h = mcc.header[col];
      int number = std::atoi(h.substr(h.find("mcc") + 3, 2).c_str());
      for (int cap = 0; cap < o.captures; ++cap) {
        CameraPatch p;
        p.id = h.substr(h.find("mcc"));
        p.conditions = {{"patch", p.id},
                        {"row", std::to_string((number - 1) / 6 + 1)},
                        {"illuminant", std::to_string(static_cast<int>(kelvins[il])) + "K"},
                        {"capture", std::to_string(cap + 1)}};
        for (size_t r = 0; r < mcc.rows.size(); ++r) {
          double w = mcc.rows[r][0];
          if (w > 1000) break;
          p.nm.push_back(w);
          p.radiance.push_back(mcc.rows[r][col] * bb(w));
        }
        p.rgb[0] = p.rgb[1] = p.rgb[2] = 1000;
        p.line = static_cast<int>(tmpl.patches.size()) + 2;
        tmpl.patches.push_back(p);
      }
    }
  }
  CameraProblem p0(tmpl, out.model);
  ModelState truth = baseline_state(p0);
  auto v0 = p0.predict(truth);
  double gmax = 0;
  for (auto& v : v0) gmax = std::max(gmax, v[1]);
  truth.base_theta[0] = 0.7 * o.full_scale / gmax;
  if (!o.effect.empty()) {
    int c = find_candidate(p0, o.effect);
    truth = with_cause(p0, truth, c);
    auto& th = truth.causes[0].theta;
    auto& spec = p0.candidates()[c];
    if (o.effect == "channel_gain") {
      th = {1 + rng.sign() * rng.uniform(0.05, 0.2), 1 + rng.sign() * rng.uniform(0.05, 0.2)};
    } else if (o.effect == "crosstalk") {
      th.assign(6, 0.0);
      int a = rng.index(6), b = (a + 1 + rng.index(5)) % 6;
      th[a] = rng.uniform(0.03, 0.08);
      th[b] = rng.uniform(0.03, 0.08);
    } else if (o.effect == "offset") {
      for (int k = 0; k < 3; ++k) th[k] = rng.sign() * rng.uniform(15, 50);
    } else if (o.effect == "nonlinearity") {
      th = {1 + rng.sign() * rng.uniform(0.03, 0.1)};
    } else if (o.effect == "qe_shift") {
      th = {rng.sign() * rng.uniform(3, 10)};
    } else if (o.effect == "nir_leak") {
      th = {rng.uniform(0.005, 0.03)};
    }
    for (size_t k = 0; k < th.size(); ++k) out.truth[spec.params[k].name] = th[k];
    out.effect_id = o.effect;
  }
  auto v = p0.predict(truth);
  out.data = tmpl;
  for (size_t i = 0; i < v.size(); ++i) {
    auto& p = out.data.patches[i];
    // Light on the patch changes a little from capture to capture (flicker, position). Drawn per
    // patch and capture: an exposure change shared by a whole illuminant would be a systematic
    // effect the baseline cannot express, not noise (docs/diagnose.md).
    double jitter = 1 + o.capture_jitter * rng.normal();
    for (int c = 0; c < 3; ++c) {
      double mean = v[i][c] * jitter;
      double e = std::max(mean, 0.0) / o.conversion_gain;
      double sd = std::sqrt(o.conversion_gain * o.conversion_gain * e + o.read_noise_dn * o.read_noise_dn);
      p.rgb[c] = mean + sd / std::sqrt(o.n_pixels) * rng.normal();
      p.sd[c] = sd;
    }
    p.n_pixels = o.n_pixels;
  }
  return out;
}

}  // namespace ofl
