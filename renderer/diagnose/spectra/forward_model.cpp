#include "renderer/diagnose/spectra/forward_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <tuple>

#include "renderer/core/errors/error.h"
#include "renderer/numerics/nnls.h"
#include "renderer/spectral/chromophores/fluorophore_library.h"
#include "renderer/spectral/chromophores/hemoglobin.h"

namespace ofl {

struct SpectraProblem::Effects {
  bool blood = false;
  BloodAbsorber absorber;
  std::vector<int> extras;  // indices into eems_
  double shift = 0, fwhm = 0, broadening = 0, edge = 0;
  bool offset = false;  // stray_light: a flat column, its level fitted per spectrum
  bool lp_leak = false;
  double emission_shift = 0;  // all fluorescence
  struct Shape {
    double shift = 0, width = 0;
    double band_center = 0, band_fwhm = 0, band_ratio = 0;
  };
  std::map<int, Shape> shape;  // per fluorophore (index into eems_)
  bool unknown = false;
  double unknown_center = 0, unknown_fwhm = 0, unknown_asymmetry = 1;
  std::vector<double> response;  // log-gain at the response knots (empty: none)
  std::vector<std::array<double, 3>> layered;  // per site: thickness, blood fraction, saturation (empty: none)
};

namespace {

bool to_number(const std::string& s, double& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end && *end == '\0';
}

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

// Mean and standard error over items of one named local quantity (items without it are skipped).
// Mean and standard error of a per-item quantity over the items that have it (and, with `when`,
// whose `when` quantity is at least `at_least`).
std::pair<double, double> mean_se(const std::vector<ItemFit>& fits, const std::string& key, bool log10_of = false,
                                  const std::string& when = "", double at_least = 0) {
  std::vector<double> v;
  for (auto& f : fits) {
    auto it = f.locals.find(key);
    if (it == f.locals.end()) continue;
    if (!when.empty()) {
      auto w = f.locals.find(when);
      if (w == f.locals.end() || !(w->second >= at_least)) continue;
    }
    double x = it->second;
    if (log10_of) {
      if (!(x > 0)) continue;
      x = std::log10(x);
    }
    v.push_back(x);
  }
  if (v.empty()) return {0, 0};
  double m = 0;
  for (double x : v) m += x;
  m /= v.size();
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  double se = v.size() > 1 ? std::sqrt(s / (v.size() - 1) / v.size()) : 0;
  return {m, se};
}

// Noise per sample of a spectrum from its second differences (variance 6 sigma^2 for white noise;
// smooth structure barely contributes, so a lower bound).
double high_frequency_noise(const Eigen::VectorXd& y) {
  double s = 0;
  long n = 0;
  for (Eigen::Index k = 1; k + 1 < y.size(); ++k) {
    double d = y[k - 1] - 2 * y[k] + y[k + 1];
    s += d * d / 6.0;
    ++n;
  }
  return n ? std::sqrt(s / n) : 0.0;
}

}  // namespace

bool leak_candidate_possible(const SpectraModel& m) {
  // The column is each light's spectrum times the long-pass's blocked fraction: it needs a
  // long-pass, and it needs nothing measured. With "leak": "measured" it adds the blocked band's
  // own level to the white-target record; with "computed" (light x long-pass at its stated
  // blocking) it frees the blocked band's transmission from the stated OD; with "none" it is the
  // only way leaked excitation light can be named (else wrong causes describe it), and it brings
  // the light's passband transmission along (add_leak_columns).
  return m.emission_filter.has_value();
}

void check_site_column(const SpectraSet& data, const LayeredCauseOptions& o) {
  if (data.spectra.empty()) return;
  const std::string& col = o.site_column;
  std::vector<std::string> values;
  bool has_column = false;
  for (auto& s : data.spectra) {
    auto it = s.conditions.find(col);
    if (it == s.conditions.end()) continue;
    has_column = true;
    if (std::find(values.begin(), values.end(), it->second) == values.end()) values.push_back(it->second);
  }
  if (!has_column)
    throw InputError("model", "/layered_tissue/site_column",
                     "column \"" + col + "\" is not in " + data.index_file + ", so no spectrum would get a layered stack");
  for (auto& site : o.sites)
    if (std::find(values.begin(), values.end(), site.site) != values.end()) return;
  std::string have, want;
  for (size_t k = 0; k < values.size() && k < 12; ++k) have += (k ? ", " : "") + (values[k].empty() ? std::string("(empty)") : values[k]);
  for (auto& site : o.sites) want += (want.empty() ? "" : ", ") + site.site;
  throw InputError("model", "/layered_tissue/site_column",
                   "no selected spectrum has a site the block describes in column \"" + col + "\" (sites: " + want + "; values there: " +
                       have + "), so no spectrum would get a layered stack");
}

std::array<double, 3> layered_theta(const double* p) {
  const double f = std::max(0.0, p[1]) + std::max(0.0, p[2]);
  return {p[0], f, f > 0 ? std::max(0.0, p[1]) / f : 1.0};
}

double emission_peak_nm(const GridEem& e) {
  auto a = e.photon_albedo();
  int ex = static_cast<int>(std::max_element(a.begin(), a.end()) - a.begin());
  int best = 0;
  double bv = -1;
  for (int em = 0; em < e.n(); ++em) {
    double v = e.at(em, ex) / e.grid.wavelength(em);
    if (v > bv) { bv = v; best = em; }
  }
  return e.grid.wavelength(best);
}

std::vector<double> gaussian_band(const WavelengthGrid& g, double center_nm, double fwhm_nm) {
  // Unit area per nm (sum * step = 1 when the band lies inside the grid).
  double sigma = std::max(fwhm_nm, 1e-3) / (2.0 * std::sqrt(2.0 * std::log(2.0)));
  std::vector<double> v(g.size());
  double norm = 1.0 / (sigma * std::sqrt(2.0 * M_PI));
  for (int i = 0; i < g.size(); ++i) {
    double x = (g.wavelength(i) - center_nm) / sigma;
    v[i] = norm * std::exp(-0.5 * x * x) * g.step_nm;
  }
  return v;
}

std::vector<double> lognormal_band(const WavelengthGrid& g, double peak_nm, double fwhm_nm, double asymmetry) {
  // Siano & Metzler's log-normal band (J. Chem. Phys. 51, 1856 (1969)) in wavenumber nu:
  //   I(nu) = exp(-ln2 / ln^2(rho) * ln^2((a - nu) / (a - nu0))),  a = nu0 + H rho / (rho^2 - 1),
  // zero beyond a; rho is the ratio of the low- to the high-wavenumber half width, H the FWHM.
  // Its area is H rho/(rho^2-1) ln(rho) sqrt(pi/ln2) exp(ln^2(rho)/(4 ln2)); rho -> 1 is the
  // Gaussian in wavenumber. Per nm it is I(nu(l)) * 1e7 / l^2 (same area), whose maximum lies
  // delta above nu0 in wavenumber: d/dnu [ln I + 2 ln nu] = 0 at nu_p = 1e7 / peak_nm, i.e.
  //   c nu_p ln(1 - delta/s) + s - delta = 0   (s = a - nu0, c = ln2 / ln^2 rho),
  //   delta = 2 sigma^2 / nu_p for the Gaussian; solved by Newton, so peak_nm is the peak one sees
  // on a plot per nm.
  const double ln2 = std::log(2.0), nup = 1e7 / peak_nm, H = std::max(1e7 * fwhm_nm / (peak_nm * peak_nm), 1e-3);
  const double rho = std::max(asymmetry, 1e-3), lr = std::log(rho);
  const bool gauss = std::fabs(lr) < 1e-4;
  const double span = gauss ? 0 : H * rho / (rho * rho - 1);
  const double c = gauss ? 0 : ln2 / (lr * lr), sigma = H / (2 * std::sqrt(2 * ln2));
  double delta = 2 * sigma * sigma / nup;
  if (!gauss)
    for (int it = 0; it < 30; ++it) {
      double q = 1 - delta / span;
      if (q <= 0) { delta = 0.5 * (delta + span * (1 - 1e-9)); continue; }  // stay inside the band
      double h = c * nup * std::log(q) + span - delta, dh = -c * nup / (span - delta) - 1;
      double step = h / dh;
      delta -= step;
      if (std::fabs(step) < 1e-9 * H) break;
    }
  const double nu0 = nup - delta, a = nu0 + span;
  const double area = gauss ? H * std::sqrt(M_PI / (4 * ln2)) : span * lr * std::sqrt(M_PI / ln2) * std::exp(lr * lr / (4 * ln2));
  std::vector<double> v(g.size(), 0.0);
  for (int i = 0; i < g.size(); ++i) {
    const double l = g.wavelength(i), nu = 1e7 / l;
    double f;
    if (gauss) {
      f = std::exp(-0.5 * (nu - nu0) * (nu - nu0) / (sigma * sigma));
    } else {
      const double r = (a - nu) / span;
      if (r <= 0) continue;
      const double t = std::log(r);
      f = std::exp(-c * t * t);
    }
    v[i] = f / area * 1e7 / (l * l) * g.step_nm;
  }
  return v;
}

double piecewise_linear(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (x.empty()) return 0;
  if (at <= x.front()) return y.front();
  if (at >= x.back()) return y.back();
  size_t k = std::upper_bound(x.begin(), x.end(), at) - x.begin();
  double t = (at - x[k - 1]) / (x[k] - x[k - 1]);
  return y[k - 1] * (1 - t) + y[k] * t;
}

int match_light(const std::vector<LightEntry>& lights, const std::map<std::string, std::string>& row,
                const std::string& nearest) {
  int best = -1;
  double best_d = 1e300;
  for (size_t k = 0; k < lights.size(); ++k) {
    bool ok = true;
    double d = 0;
    for (auto& [col, val] : lights[k].when) {
      auto it = row.find(col);
      std::string cell = it == row.end() ? std::string() : it->second;
      if (col == nearest) {
        double a, b;
        if (!to_number(cell, a) || !to_number(val, b)) { ok = false; break; }
        d = std::fabs(a - b);
      } else if (!cell_matches(cell, val)) {
        ok = false;
        break;
      }
    }
    if (ok && d < best_d) { best_d = d; best = static_cast<int>(k); }
  }
  return best;
}

namespace {

// The data's wavelength span.
std::pair<double, double> data_span(const SpectraSet& data) {
  double lo = 1e9, hi = 0;
  for (auto& s : data.spectra) {
    lo = std::min(lo, s.nm.front());
    hi = std::max(hi, s.nm.back());
  }
  return {lo, hi};
}

// The grid covers the data and the LED bands with room for shifts and blur at the ends.
WavelengthGrid model_grid(double lo, double hi, double step) {
  const double pad = 40;
  double gmin = std::floor((std::min(lo, 350.0) - pad) / step) * step;
  if (gmin < step) gmin = step;
  double gmax = gmin + step * std::ceil((hi + pad - gmin) / step);
  WavelengthGrid grid{gmin, gmax, step};
  if (auto p = grid.problem(); !p.empty()) throw InputError("model", "/grid_step_nm", p);
  return grid;
}

// The baseline fluorophores, then every extra candidate (the library's others by default).
std::vector<std::string> fluorophore_list(const SpectraModel& model) {
  std::vector<std::string> names = model.fluorophores;
  std::vector<std::string> extras;
  if (model.candidates.extra_fluorophore) {
    extras = model.candidates.extra_from;
    if (extras.empty())
      for (auto& e : fluorophore_library())
        if (std::find(names.begin(), names.end(), e.name) == names.end()) extras.push_back(e.name);
    for (auto& e : extras)
      if (std::find(names.begin(), names.end(), e) != names.end())
        throw InputError("model", "/candidates/extra_fluorophore/from", "\"" + e + "\" is already in the baseline");
  }
  for (auto& e : extras) names.push_back(e);
  return names;
}

// "no light in the model matches this row ( col=value ...)": the row's values of every column a
// light's `when` names.
std::string light_conditions(const std::vector<LightEntry>& lights, const MeasuredSpectrum& s) {
  std::string cond;
  for (auto& L : lights)
    for (auto& [c, v] : L.when) {
      (void)v;
      auto f = s.conditions.find(c);
      if (cond.find(c + "=") == std::string::npos) cond += " " + c + "=" + (f == s.conditions.end() ? "" : f->second);
    }
  return "no light in the model matches this row (" + cond.substr(cond.empty() ? 0 : 1) + ")";
}

}  // namespace

SpectraProblem::SpectraProblem(SpectraSet data, SpectraModel model) : data_(std::move(data)), model_(std::move(model)) {
  if (model_.lights.empty()) throw InputError("model", "/lights", "no excitation lights given");
  if (model_.fluorophores.empty()) throw InputError("model", "/fluorophores", "the baseline needs at least one fluorophore");
  auto [lo, hi] = data_span(data_);
  grid_ = model_grid(lo, hi, model_.grid_step_nm);
  eem_names_ = fluorophore_list(model_);
  for (auto& n : eem_names_) eems_.push_back(load_fluorophore(n, grid_, model_.base_dir));
  make_candidates(lo, hi);
  for (auto& L : model_.lights) lights_.push_back(light_basis(L));
  add_layered_candidate();
  replicate_scoped_params();
  for (auto& c : model_.shared_by) {
    bool any = false;
    for (auto& sp : data_.spectra) any = any || (sp.conditions.count(c) && !sp.conditions.at(c).empty());
    if (!any && !data_.spectra.empty())
      throw InputError("model", "/shared_concentrations", "column \"" + c + "\" is empty or missing for every spectrum");
  }
  for (int i = 0; i < grid_.size(); ++i)
    if (grid_.wavelength(i) >= model_.fit_min_nm && grid_.wavelength(i) <= model_.fit_max_nm && grid_.wavelength(i) >= lo &&
        grid_.wavelength(i) <= hi)
      fit_grid_.push_back(i);
  for (size_t i = 0; i < data_.spectra.size(); ++i) items_.push_back(make_item(static_cast<int>(i)));
}

void SpectraProblem::make_candidates(double lo, double hi) {
  SpectraCandidateOptions copt = model_.candidates;
  copt.leak = copt.leak && leak_candidate_possible(model_);
  copt.leak_passband = model_.leak == LeakSource::kNone;
  std::erase_if(copt.plausible, [](const SpectraCandidateOptions::Range& r) { return r.candidate == "layered_tissue"; });  // its own
  std::vector<FluorophoreInfo> info;
  for (size_t k = 0; k < eem_names_.size(); ++k)
    info.push_back({eem_names_[k], emission_peak_nm(eems_[k]), k < model_.fluorophores.size()});
  range_ = {std::max(model_.fit_min_nm, lo), std::min(model_.fit_max_nm, hi)};
  candidates_ = spectra_candidates(copt, info, range_);
}

SpectraProblem::LightBasis SpectraProblem::light_basis(const LightEntry& L) const {
  const int N = grid_.size();
  LightBasis b;
  auto e = tabulate(L.spectrum, grid_);
  if (model_.excitation_filter) {
    auto t = tabulate(model_.excitation_filter->at_angle(0), grid_);
    for (int i = 0; i < N; ++i) e[i] *= t[i];
  }
  for (double& v : e) v = std::max(v, 0.0);
  // The LED band: from the peak outwards until the light falls below the instrument floor.
  int pk = static_cast<int>(std::max_element(e.begin(), e.end()) - e.begin());
  double floor = model_.light_floor_fraction * e[pk];
  b.e_tail.assign(N, 0.0);
  for (int i = pk; i < N && e[i] >= floor; ++i) b.e_tail[i] = e[i];
  for (int i = pk; i >= 0 && e[i] >= floor; --i) b.e_tail[i] = e[i];
  // Photon units for the EEM (photons per joule ~ wavelength), back to energy on the way out.
  std::vector<double> eph(N);
  for (int i = 0; i < N; ++i) eph[i] = b.e_tail[i] * grid_.wavelength(i);
  for (auto& eem : eems_) {
    auto col = eem.apply(eph);
    for (int i = 0; i < N; ++i) col[i] /= grid_.wavelength(i);
    b.fluor.push_back(std::move(col));
  }
  // The white-target record through the long-pass is kept whole: beyond the LED band it holds a
  // broad floor (480-800 nm) that is 0.28-0.31 of the 480-500 nm level at every current of an LED
  // (405 nm: 90, 560, 980 mA), i.e. light the LED puts through the filters, which scales with the
  // reflected excitation like the rest of the leak, not a dark offset of the instrument.
  if (L.leak) b.leak = tabulate(*L.leak, grid_);
  b.e = std::move(e);
  return b;
}

SpectraProblem::Item SpectraProblem::make_item(int index) const {
  const MeasuredSpectrum& s = data_.spectra[index];
  const int N = grid_.size();
  Item it;
  it.light = match_light(model_.lights, s.conditions, model_.nearest_column);
  if (it.light < 0) throw InputError(data_.index_file, "line " + std::to_string(s.index_line), light_conditions(model_.lights, s));
  std::vector<double> y;
  for (size_t k = 0; k < s.nm.size(); ++k)
    if (s.nm[k] >= model_.fit_min_nm && s.nm[k] <= model_.fit_max_nm) {
      it.nm.push_back(s.nm[k]);
      y.push_back(s.value[k]);
    }
  if (it.nm.size() < 8) throw InputError(s.file, "wavelength_nm", "fewer than 8 samples inside the fit range");
  double m = 0;
  for (double v : y) m += v;
  m /= y.size();
  if (!(m > 0)) throw InputError(s.file, "radiance", "mean radiance over the fit range is not positive");
  it.mean = m;
  it.y = Eigen::Map<Eigen::VectorXd>(y.data(), static_cast<Eigen::Index>(y.size())) / m;
  it.noise = high_frequency_noise(it.y);
  for (int kind : {kTissueScope, kInstrumentScope}) {
    const auto& values = scopes_[kind].values;
    it.scope[kind] = static_cast<int>(std::find(values.begin(), values.end(), scope_key(s, kind)) - values.begin());
  }
  for (double nm : it.nm) {
    double x = (nm - grid_.min_nm) / grid_.step_nm;
    int a = std::clamp(static_cast<int>(std::floor(x)), 0, N - 2);
    it.lo.push_back(a);
    it.w.push_back(std::clamp(x - a, 0.0, 1.0));
  }
  if (!sites_.empty()) {
    std::string site = condition(index, model_.layered.site_column);
    for (size_t q = 0; q < sites_.size(); ++q)
      if (sites_[q]->site() == site) it.site = static_cast<int>(q);
  }
  return it;
}

std::string SpectraProblem::condition(int i, const std::string& column) const {
  auto& c = data_.spectra[i].conditions;
  auto it = c.find(column);
  return it == c.end() ? std::string() : it->second;
}

void SpectraProblem::add_layered_candidate() {
  LayeredCauseOptions o = model_.layered;
  if (!o.enabled || o.sites.empty()) {
    for (auto& r : model_.candidates.plausible)
      if (r.candidate == "layered_tissue")
        throw InputError("model", "/plausible/layered_tissue", "the model has no (enabled) layered_tissue block");
    return;
  }
  check_site_column(data_, o);
  // Walk only where the lights emit and the fit looks (with room for shifts and blur).
  o.min_nm = 1e9;
  for (auto& L : lights_)
    for (int i = 0; i < grid_.size(); ++i)
      if (L.e_tail[i] > 0) o.min_nm = std::min(o.min_nm, grid_.wavelength(i) - 10);
  o.max_nm = range_.max_nm + 30;
  std::vector<std::vector<double>> light_e;
  for (auto& L : lights_) light_e.push_back(L.e_tail);
  CandidateSpec c{"layered_tissue", "layered_tissue",
                  "layered tissue (epithelial thickness, oxy- and deoxygenated blood per site)", {}, 0, ""};
  const double fmax = o.blood_fraction.back();
  for (auto& spec : o.sites) {
    sites_.push_back(std::make_shared<LayeredSite>(spec, o, grid_, eem_names_, eems_, light_e));
    const std::string& s = spec.site;
    auto& t = o.thickness_mm;
    // Blood as oxy- and deoxygenated volume fractions (fraction = their sum, saturation = oxy /
    // sum), as blood_absorption has oxy and deoxy: fully oxygenated blood rests on deoxy's null
    // bound, which is not a bound the fit is pushed to.
    c.params.push_back({"thickness_mm:" + s, "mm", std::clamp(0.25, t.front(), t.back()), t.front(), t.back(), 0.01, {}});
    c.params.push_back({"oxy_blood_fraction:" + s, "volume fraction", std::min(0.01, fmax), 0.0, fmax, 0.001,
                        {std::min(0.005, fmax), std::min(0.03, fmax)}});
    c.params.push_back({"deoxy_blood_fraction:" + s, "volume fraction", 0.0, 0.0, fmax, 0.001, {0.0, std::min(0.005, fmax)}});
    for (const char* q : {"oxy_blood_fraction:", "deoxy_blood_fraction:"})
      c.plausible.push_back({q + s, 0.0, 0.1,
                             "blood in oral mucosa's stroma: up to 10 % by volume (the presets' 1.25 % reproduces the stromal "
                             "absorption of Pavlova et al. 2008)"});
  }
  std::vector<CandidateSpec> one = {std::move(c)};
  apply_plausible(one, model_.candidates.plausible);
  candidates_.push_back(std::move(one[0]));
}

std::string SpectraProblem::scope_key(const MeasuredSpectrum& s, int kind) const {
  std::string k;
  for (auto& c : scopes_[kind].columns) {
    auto it = s.conditions.find(c);
    k += (k.empty() ? "" : "/") + (it == s.conditions.end() ? std::string() : it->second);
  }
  return k;
}

void SpectraProblem::replicate_scoped_params() {
  scope_params_.assign(candidates_.size(), 0);
  scope_kind_.assign(candidates_.size(), 0);
  scopes_[kTissueScope].columns = model_.tissue_per;
  if (!model_.instrument_column.empty()) scopes_[kInstrumentScope].columns = {model_.instrument_column};
  const char* field[2] = {"/tissue_per", "/instrument_column"};
  for (int kind : {kTissueScope, kInstrumentScope}) {
    Scopes& sc = scopes_[kind];
    if (sc.columns.empty()) continue;
    for (auto& c : sc.columns) {
      bool any = false;
      for (auto& sp : data_.spectra) any = any || sp.conditions.count(c) > 0;
      if (!any && !data_.spectra.empty()) throw InputError("model", field[kind], "column \"" + c + "\" is not in " + data_.index_file);
    }
    sc.values.clear();
    for (auto& sp : data_.spectra)
      if (std::find(sc.values.begin(), sc.values.end(), scope_key(sp, kind)) == sc.values.end()) sc.values.push_back(scope_key(sp, kind));
    if (sc.values.empty()) sc.values = {""};
  }
  // Tissue causes with global parameters get one copy per tissue ("oxy_uM_cm@B"), instrument
  // causes one per instrument when the model names an instrument column; the layered cause already
  // has one set per site and stays as it is.
  for (size_t k = 0; k < candidates_.size(); ++k) {
    CandidateSpec& c = candidates_[k];
    const int kind = c.instrument ? kInstrumentScope : kTissueScope;
    if (scopes_[kind].columns.empty() || c.params.empty() || spectra_cause(c) == SpectraCause::kLayered) continue;
    const std::vector<std::string>& values = scopes_[kind].values;
    const std::vector<ParamSpec> base = c.params;
    const auto base_plausible = c.plausible;
    c.params.clear();
    c.plausible.clear();
    for (size_t v = 0; v < values.size(); ++v)
      for (size_t j = 0; j < base.size(); ++j) {
        ParamSpec ps = base[j];
        ps.name += "@" + values[v];
        if (v > 0) ps.tie_start = static_cast<int>(j);
        c.params.push_back(ps);
      }
    for (auto& q : base_plausible) {
      bool is_param = false;
      for (auto& ps : base) is_param = is_param || ps.name == q.quantity;
      if (!is_param) { c.plausible.push_back(q); continue; }
      for (auto& v : values) {
        auto r = q;
        r.quantity += "@" + v;
        c.plausible.push_back(r);
      }
    }
    scope_params_[k] = static_cast<int>(base.size());
    scope_kind_[k] = kind;
  }
}

void SpectraProblem::fill_unfitted(ModelState& state, const std::vector<int>& fitted_items) const {
  std::vector<char> seen[2];
  for (int kind : {kTissueScope, kInstrumentScope}) {
    seen[kind].assign(scopes_[kind].values.size(), 0);
    for (int i : fitted_items) seen[kind][items_[i].scope[kind]] = 1;
  }
  for (auto& a : state.causes) {
    const int P = scope_params_[a.candidate];
    if (P == 0) continue;
    const std::vector<char>& fitted = seen[scope_kind_[a.candidate]];
    for (int j = 0; j < P; ++j) {
      double m = 0;
      int n = 0;
      for (size_t v = 0; v < fitted.size(); ++v)
        if (fitted[v]) { m += a.theta[v * P + j]; ++n; }
      if (n == 0) continue;
      for (size_t v = 0; v < fitted.size(); ++v)
        if (!fitted[v]) a.theta[v * P + j] = m / n;
    }
  }
}

SpectraProblem::Effects SpectraProblem::decode(const ModelState& s, const std::array<int, 2>& scope) const {
  Effects fx;
  for (auto& cause : s.causes) {
    const CandidateSpec& c = candidates_[cause.candidate];
    // The item's own copy of a per-tissue or per-instrument cause's parameters.
    ActiveCause a{cause.candidate, {}};
    const int P = scope_params_[cause.candidate], v = scope[scope_kind_[cause.candidate]];
    if (P > 0)
      a.theta.assign(cause.theta.begin() + v * P, cause.theta.begin() + (v + 1) * P);
    else
      a.theta = cause.theta;
    switch (spectra_cause(c)) {
      case SpectraCause::kBlood:
        fx.blood = true;
        fx.absorber.oxy_uM_cm = a.theta[0];
        fx.absorber.deoxy_uM_cm = a.theta[1];
        fx.absorber.excitation_path_factor = model_.candidates.blood_excitation_path_factor;
        break;
      case SpectraCause::kExtraFluorophore: {
        auto n = extra_fluorophore_name(c);
        for (size_t k = model_.fluorophores.size(); k < eem_names_.size(); ++k)
          if (eem_names_[k] == n) fx.extras.push_back(static_cast<int>(k));
        break;
      }
      case SpectraCause::kShift: fx.shift = a.theta[0]; break;
      case SpectraCause::kBandwidth: fx.fwhm = a.theta[0]; break;
      case SpectraCause::kBroadening: fx.broadening = a.theta[0]; break;
      case SpectraCause::kStray: fx.offset = true; break;
      case SpectraCause::kLeak: fx.lp_leak = true; break;
      case SpectraCause::kEdge: fx.edge = a.theta[0]; break;
      case SpectraCause::kEmissionShift: fx.emission_shift = a.theta[0]; break;
      case SpectraCause::kFluorShift: fx.shape[eem_index(cause_fluorophore(c))].shift = a.theta[0]; break;
      case SpectraCause::kFluorWidth: fx.shape[eem_index(cause_fluorophore(c))].width = a.theta[0]; break;
      case SpectraCause::kFluorWidthEach:
        for (size_t k = 0; k < a.theta.size(); ++k) fx.shape[static_cast<int>(k)].width = a.theta[k];
        break;
      case SpectraCause::kSecondBand: {
        auto& sh = fx.shape[eem_index(cause_fluorophore(c))];
        sh.band_center = a.theta[0];
        sh.band_fwhm = a.theta[1];
        sh.band_ratio = a.theta[2];
        break;
      }
      case SpectraCause::kUnknownBand:
        fx.unknown = true;
        fx.unknown_center = a.theta[0];
        fx.unknown_fwhm = a.theta[1];
        fx.unknown_asymmetry = a.theta[2];
        break;
      case SpectraCause::kResponse: fx.response = a.theta; break;
      case SpectraCause::kLayered:
        for (size_t q = 0; q + 2 < a.theta.size(); q += 3) fx.layered.push_back(layered_theta(&a.theta[q]));
        break;
    }
  }
  return fx;
}

void SpectraProblem::longpass(const Effects& fx, std::vector<double>& tlp, std::vector<double>& block) const {
  const int N = grid_.size();
  tlp.assign(N, 1.0);
  block.assign(N, 0.0);
  if (!model_.emission_filter) return;
  OpticalFilter f = *model_.emission_filter;
  f.edge_nm += fx.edge;
  f.edge2_nm += f.edge2_nm > 0 ? fx.edge : 0;
  tlp = tabulate(f.at_angle(0), grid_);
  double tmin = f.kind == OpticalFilter::Kind::kMeasured ? 0.0 : std::pow(10.0, -f.od);
  double span = std::max(f.peak - tmin, 1e-12);
  for (int i = 0; i < N; ++i) block[i] = std::clamp((f.peak - tlp[i]) / span, 0.0, 1.0);
}

void SpectraProblem::add_leak_columns(int light, const Effects& fx, const std::vector<double>& tlp,
                                      const std::vector<double>& block, std::vector<std::vector<double>>& cols,
                                      std::vector<std::string>* names) const {
  const LightBasis& L = lights_[light];
  const int N = grid_.size();
  if (model_.leak != LeakSource::kNone) {
    std::vector<double> col(N);
    if (model_.leak == LeakSource::kMeasured && !L.leak.empty())
      col = L.leak;
    else
      for (int i = 0; i < N; ++i) col[i] = L.e_tail[i] * tlp[i];
    cols.push_back(std::move(col));
    if (names) names->push_back("leak");
  }
  if (fx.lp_leak) {
    std::vector<double> col(N);
    for (int i = 0; i < N; ++i) col[i] = L.e_tail[i] * block[i];
    cols.push_back(std::move(col));
    if (names) names->push_back("longpass_leak");
    // Without a leak column in the baseline, the light reflected through the passband (what
    // "leak": "computed" puts in the baseline) is the candidate's too, with its own amplitude (the
    // tissue's reflectance): the blocked band's level relative to it is what the filter's OD is.
    if (model_.leak == LeakSource::kNone) {
      std::vector<double> pass(N);
      for (int i = 0; i < N; ++i) pass[i] = L.e_tail[i] * tlp[i];
      cols.push_back(std::move(pass));
      if (names) names->push_back("leak_passband");
    }
  }
}

void SpectraProblem::apply_instrument(std::vector<std::vector<double>>& cols, const Effects& fx) const {
  // The instrument, in the order light meets it: slit blur, wavelength scale (the detector-side
  // offset is a column of its own, add_offset_column).
  double fwhm = std::sqrt(model_.instrument_fwhm_nm * model_.instrument_fwhm_nm + fx.fwhm * fx.fwhm);
  for (auto& c : cols) {
    if (fwhm > 0) gaussian_blur(c, grid_.step_nm, fwhm);
    if (fx.shift != 0) shift_samples(c, grid_.step_nm, fx.shift);
  }
  if (!fx.response.empty()) {
    auto knots = response_knots(range_);
    if (knots.size() != fx.response.size()) throw std::logic_error("instrument_response: parameters do not match the knots");
    std::vector<double> g(grid_.size());
    for (int i = 0; i < grid_.size(); ++i) g[i] = std::exp(piecewise_linear(knots, fx.response, grid_.wavelength(i)));
    for (auto& c : cols)
      for (int i = 0; i < grid_.size(); ++i) c[i] *= g[i];
  }
}

void SpectraProblem::add_offset_column(const Effects& fx, std::vector<std::vector<double>>& cols,
                                       std::vector<std::string>* names) const {
  // Detector side: after the filters, the slit and the responsivity, so flat in what is recorded
  // (a dark level that was not subtracted, or stray light spread evenly over the array). Its level
  // is each spectrum's own amplitude: it need not scale with the tissue's signal.
  if (!fx.offset) return;
  cols.emplace_back(grid_.size(), 1.0);
  if (names) names->push_back("stray_light");
}

int SpectraProblem::eem_index(const std::string& name) const {
  for (size_t k = 0; k < eem_names_.size(); ++k)
    if (eem_names_[k] == name) return static_cast<int>(k);
  throw std::logic_error("no fluorophore " + name + " in the diagnosis model");
}

void SpectraProblem::shape_emission(int k, const Effects& fx, std::vector<double>& col) const {
  // Per fluorophore first (its own band shape), then what acts on all fluorescence.
  auto it = fx.shape.find(k);
  if (it != fx.shape.end()) {
    const Effects::Shape& sh = it->second;
    if (sh.band_ratio > 0) {
      double area = 0;
      for (double v : col) area += v;
      auto band = gaussian_band(grid_, sh.band_center, sh.band_fwhm);
      for (int i = 0; i < grid_.size(); ++i) col[i] += sh.band_ratio * area * band[i];
    }
    if (sh.width > 0) gaussian_blur(col, grid_.step_nm, sh.width);
    if (sh.shift != 0) shift_samples(col, grid_.step_nm, sh.shift);
  }
  if (fx.broadening > 0) gaussian_blur(col, grid_.step_nm, fx.broadening);
  if (fx.emission_shift != 0) shift_samples(col, grid_.step_nm, fx.emission_shift);
}

std::vector<std::vector<double>> SpectraProblem::grid_columns(int light, int site, const Effects& fx,
                                                              std::vector<std::string>* names) const {
  const LightBasis& L = lights_[light];
  const int N = grid_.size();
  std::vector<double> tb(N, 1.0), tlp, block;
  if (fx.blood) tb = blood_transmittance(fx.absorber, grid_);
  longpass(fx, tlp, block);
  std::vector<std::vector<double>> cols;
  std::vector<int> which;
  for (size_t k = 0; k < model_.fluorophores.size(); ++k) which.push_back(static_cast<int>(k));
  for (int k : fx.extras) which.push_back(k);
  const bool ex_blood = fx.blood && fx.absorber.excitation_path_factor != 0;
  std::vector<double> eph;
  if (ex_blood) {
    eph.resize(N);
    for (int i = 0; i < N; ++i)
      eph[i] = L.e_tail[i] * grid_.wavelength(i) * std::pow(tb[i], fx.absorber.excitation_path_factor);
  }
  for (int k : which) {
    std::vector<double> col;
    if (ex_blood) {
      col = eems_[k].apply(eph);
      for (int i = 0; i < N; ++i) col[i] /= grid_.wavelength(i);
    } else {
      col = L.fluor[k];
    }
    shape_emission(k, fx, col);
    if (!fx.layered.empty() && site >= 0 && sites_[site]->holds(k)) {
      auto f = sites_[site]->factor(k, light, fx.layered[site]);
      for (int i = 0; i < N; ++i) col[i] *= f[i];
    }
    for (int i = 0; i < N; ++i) col[i] *= tb[i] * tlp[i];
    cols.push_back(std::move(col));
    if (names) names->push_back(eem_names_[k]);
  }
  if (fx.unknown) {
    auto col = lognormal_band(grid_, fx.unknown_center, fx.unknown_fwhm, fx.unknown_asymmetry);
    for (int i = 0; i < N; ++i) col[i] *= tb[i] * tlp[i];
    cols.push_back(std::move(col));
    if (names) names->push_back("unknown_band");
  }
  add_leak_columns(light, fx, tlp, block, cols, names);
  apply_instrument(cols, fx);
  add_offset_column(fx, cols, names);
  return cols;
}

SpectraProblem::Design SpectraProblem::instrument_design(const ModelState& state, int item,
                                                         const std::vector<double>& radiance) const {
  if (static_cast<int>(radiance.size()) != grid_.size())
    throw std::invalid_argument("instrument_design: radiance is not on the model grid");
  Effects fx = decode(state, items_[item].scope);
  std::vector<double> tlp, block;
  longpass(fx, tlp, block);
  std::vector<std::vector<double>> cols(1, radiance);
  for (int i = 0; i < grid_.size(); ++i) cols[0][i] *= tlp[i];
  Design d;
  d.names.push_back("radiance");
  add_leak_columns(items_[item].light, fx, tlp, block, cols, &d.names);
  apply_instrument(cols, fx);
  add_offset_column(fx, cols, &d.names);
  d.A = sample(cols, items_[item]);
  return d;
}

Eigen::MatrixXd SpectraProblem::sample(const std::vector<std::vector<double>>& cols, const Item& it) const {
  Eigen::MatrixXd A(static_cast<Eigen::Index>(it.nm.size()), static_cast<Eigen::Index>(cols.size()));
  for (size_t j = 0; j < cols.size(); ++j)
    for (size_t r = 0; r < it.nm.size(); ++r)
      A(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(j)) =
          cols[j][it.lo[r]] * (1 - it.w[r]) + cols[j][it.lo[r] + 1] * it.w[r];
  return A;
}

namespace {

// An item's fit from its design A and coefficients x (x in the columns' units per unit y).
// The detector-side offset of one spectrum against the instrument's level (the peak of what else
// the spectrum records over the fit range), against the tissue's mean signal, in the data's own
// units, and against the spectrum's high-frequency noise.
void offset_locals(ItemFit& f, const Eigen::VectorXd& offset, double mean, double noise) {
  const double level = offset.size() ? offset[0] : 0.0;
  const Eigen::VectorXd rest = f.predicted - offset;
  const double peak = rest.size() ? rest.maxCoeff() : 0.0, avg = rest.size() ? rest.mean() : 0.0;
  f.locals["offset_of_peak"] = peak > 0 ? level / peak : 0;
  f.locals["offset_of_mean"] = avg > 0 ? level / avg : 0;
  f.locals["offset_radiance"] = level * mean;
  f.locals["offset_to_noise"] = noise > 0 ? level / noise : 0;
}

ItemFit item_fit(const Eigen::VectorXd& y, const Eigen::MatrixXd& A, const Eigen::VectorXd& x,
                 const std::vector<std::string>& names, double mean, int dofs, double noise) {
  ItemFit f;
  f.measured = y;
  f.predicted = A * x;
  f.residual = y - f.predicted;
  f.local_dofs = dofs;
  double total = f.predicted.mean();
  for (Eigen::Index j = 0; j < A.cols(); ++j) {
    double part = (A.col(j) * x[j]).mean();
    f.locals["fraction:" + names[j]] = total > 0 ? part / total : 0;
    f.locals["amount:" + names[j]] = x[j] * mean;  // absolute: per unit of the column (render_loop.h)
    if (names[j] == "longpass_leak") f.locals["leak_ratio"] = x[j] * mean;
    if (names[j] == "stray_light") offset_locals(f, A.col(j) * x[j], mean, noise);
  }
  return f;
}

}  // namespace

std::string SpectraProblem::visit_of(int i) const {
  std::string k;
  for (auto& c : model_.shared_by) k += condition(i, c) + '\x1f';
  return k;
}

std::vector<ItemFit> SpectraProblem::evaluate(const ModelState& state, const std::vector<int>& items) const {
  std::map<std::array<int, 2>, Effects> fx_of;  // per tissue and instrument (one unless the model has either)
  std::map<std::tuple<int, int, std::array<int, 2>>, std::vector<std::vector<double>>> cache;
  std::vector<std::string> names;
  std::vector<Eigen::MatrixXd> A(items.size());
  for (size_t q = 0; q < items.size(); ++q) {
    const Item& it = items_[items[q]];
    auto f = fx_of.find(it.scope);
    if (f == fx_of.end()) f = fx_of.emplace(it.scope, decode(state, it.scope)).first;
    const Effects& fx = f->second;
    const std::tuple<int, int, std::array<int, 2>> key(it.light, fx.layered.empty() ? -1 : it.site, it.scope);
    auto c = cache.find(key);
    if (c == cache.end()) {
      std::vector<std::string> nm;
      c = cache.emplace(key, grid_columns(it.light, std::get<1>(key), fx, &nm)).first;
      names = nm;
    }
    A[q] = sample(c->second, it);
  }
  std::vector<ItemFit> out(items.size());
  if (model_.shared_by.empty()) {
    for (size_t q = 0; q < items.size(); ++q) {
      const Item& it = items_[items[q]];
      NnlsResult r = nnls(A[q], it.y);
      out[q] = item_fit(it.y, A[q], r.x, names, it.mean, r.active, it.noise);
    }
    return out;
  }
  std::map<std::string, std::vector<size_t>> visits;
  for (size_t q = 0; q < items.size(); ++q) visits[visit_of(items[q])].push_back(q);
  for (auto& [key, group] : visits) fit_visit(items, group, A, names, out);
  return out;
}

void SpectraProblem::fit_visit(const std::vector<int>& items, const std::vector<size_t>& group,
                               const std::vector<Eigen::MatrixXd>& A, const std::vector<std::string>& names,
                               std::vector<ItemFit>& out) const {
  // One set of fluorophore amounts for every spectrum of a visit (absolute: a spectrum's
  // columns divided by its mean, since y is), each spectrum keeping its own leak and band columns.
  std::vector<int> shared, local;
  for (size_t j = 0; j < names.size(); ++j)
    (std::find(eem_names_.begin(), eem_names_.end(), names[j]) != eem_names_.end() ? shared : local).push_back(int(j));
  const Eigen::Index S = Eigen::Index(shared.size()), L = Eigen::Index(local.size());
  Eigen::Index rows = 0;
  for (size_t q : group) rows += A[q].rows();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(rows, S + L * Eigen::Index(group.size()));
  Eigen::VectorXd y(rows);
  Eigen::Index r0 = 0;
  for (size_t g = 0; g < group.size(); ++g) {
    const size_t q = group[g];
    const Item& it = items_[items[q]];
    const Eigen::Index n = A[q].rows();
    for (Eigen::Index j = 0; j < S; ++j) M.block(r0, j, n, 1) = A[q].col(shared[j]) / it.mean;
    for (Eigen::Index j = 0; j < L; ++j) M.block(r0, S + L * Eigen::Index(g) + j, n, 1) = A[q].col(local[j]);
    y.segment(r0, n) = it.y;
    r0 += n;
  }
  NnlsResult r = nnls(M, y);
  int shared_active = 0;
  for (Eigen::Index j = 0; j < S; ++j) shared_active += r.x[j] > 0;
  for (size_t g = 0; g < group.size(); ++g) {
    const size_t q = group[g];
    const Item& it = items_[items[q]];
    Eigen::VectorXd x = Eigen::VectorXd::Zero(A[q].cols());
    int dofs = g == 0 ? shared_active : 0;  // the shared amounts are counted once per visit
    for (Eigen::Index j = 0; j < S; ++j) x[shared[j]] = r.x[j] / it.mean;
    for (Eigen::Index j = 0; j < L; ++j) {
      x[local[j]] = r.x[S + L * Eigen::Index(g) + j];
      dofs += x[local[j]] > 0;
    }
    out[q] = item_fit(it.y, A[q], x, names, it.mean, dofs, it.noise);
  }
}

SpectraProblem::Design SpectraProblem::design(const ModelState& state, int item) const {
  Effects fx = decode(state, items_[item].scope);
  Design d;
  auto cols = grid_columns(items_[item].light, items_[item].site, fx, &d.names);
  d.A = sample(cols, items_[item]);
  return d;
}

double SpectraProblem::fallback_noise_variance() const {
  // High-frequency scatter: for white noise the second difference has variance 6 sigma^2. Smooth
  // spectral structure barely contributes, so this is a lower bound of the real noise floor.
  double s = 0;
  long n = 0;
  for (auto& it : items_)
    for (Eigen::Index k = 1; k + 1 < it.y.size(); ++k) {
      double d = it.y[k - 1] - 2 * it.y[k] + it.y[k + 1];
      s += d * d / 6.0;
      ++n;
    }
  return n ? s / n : -1;
}

double SpectraProblem::centred_sum_of_squares(int i) const {
  const auto& y = items_[i].y;
  return (y.array() - y.mean()).square().sum();
}

std::vector<DerivedParam> SpectraProblem::derived_params(const CandidateSpec& c, const std::vector<ItemFit>& fits,
                                                         const std::vector<int>& items) const {
  std::vector<DerivedParam> d;
  switch (spectra_cause(c)) {
    case SpectraCause::kExtraFluorophore: {
      auto [m, se] = mean_se(fits, "fraction:" + extra_fluorophore_name(c));
      d.push_back({"mean_fraction", "of the predicted signal", m, se});
      break;
    }
    case SpectraCause::kLeak: {
      // Over the spectra where the leak carries at least 0.5 % of the signal: elsewhere (an LED
      // whose light the long-pass blocks entirely) its amplitude is not determined, and a tiny
      // column with an arbitrary amplitude would pull the mean of the logarithms anywhere.
      auto [m, se] = mean_se(fits, "leak_ratio", true, "fraction:longpass_leak", 0.005);
      d.push_back({"effective_od", "decadic (tissue reflectance included)", -m, se});
      auto [f, fse] = mean_se(fits, "fraction:longpass_leak");
      d.push_back({"mean_fraction", "of the predicted signal", f, fse});
      if (model_.leak == LeakSource::kNone) {
        auto [q, qse] = mean_se(fits, "fraction:leak_passband");
        d.push_back({"passband_fraction", "of the predicted signal", q, qse});
      }
      break;
    }
    case SpectraCause::kStray: {
      auto [p, pse] = mean_se(fits, "offset_of_peak");
      d.push_back({"fraction_of_peak", "of the spectrum's recorded peak", p, pse});
      auto [m, mse] = mean_se(fits, "offset_of_mean");
      d.push_back({"fraction", "of the tissue's mean signal", m, mse});
      auto [r, rse] = mean_se(fits, "offset_radiance");
      d.push_back({"offset", "in the data's units", r, rse});
      auto [n, nse] = mean_se(fits, "offset_to_noise");
      d.push_back({"offset_to_noise", "x the spectrum's high-frequency noise", n, nse});
      break;
    }
    case SpectraCause::kUnknownBand: {
      auto [m, se] = mean_se(fits, "fraction:unknown_band");
      d.push_back({"mean_fraction", "of the predicted signal", m, se});
      break;
    }
    default: break;
  }
  return d;
}

std::string SpectraProblem::plain_words(const CandidateSpec& c, const std::vector<double>& th,
                                        const std::vector<double>& u, const std::vector<DerivedParam>& d) const {
  int P = 0, kind = 0;
  for (size_t k = 0; k < candidates_.size(); ++k)
    if (candidates_[k].id == c.id) { P = scope_params_[k]; kind = scope_kind_[k]; }
  const std::vector<std::string>& values = scopes_[kind].values;
  if (P == 0 || th.size() != values.size() * P) return plain_words_one(c, th, u, d);
  // One set per tissue or instrument: each in words, named by its value.
  std::string s;
  for (size_t q = 0; q < values.size(); ++q) {
    std::vector<double> t(th.begin() + q * P, th.begin() + (q + 1) * P), v(P, 0.0);
    if (u.size() == th.size()) v.assign(u.begin() + q * P, u.begin() + (q + 1) * P);
    s += (q ? " " : "") + std::string("[") + values[q] + "] " + plain_words_one(c, t, v, d);
  }
  return s;
}

std::string SpectraProblem::plain_words_one(const CandidateSpec& c, const std::vector<double>& th,
                                            const std::vector<double>& u, const std::vector<DerivedParam>& d) const {
  auto pm = [](double v, double e, const char* f) { return fmt(f, v) + " +/- " + fmt(f, e); };
  switch (spectra_cause(c)) {
    case SpectraCause::kBlood: {
      BloodAbsorber b;
      b.oxy_uM_cm = th[0];
      b.deoxy_uM_cm = th[1];
      std::string s = "Blood absorbs the fluorescence on its way out of the tissue (Beer-Lambert, oxy- and deoxy-hemoglobin): "
                      "oxy " + pm(th[0], u[0], "%.2f") + " umol/L*cm, deoxy " + pm(th[1], u[1], "%.2f") +
                      " umol/L*cm (saturation " + fmt("%.0f", 100 * b.saturation()) + "%), optical density " +
                      fmt("%.3f", blood_optical_density(b, 542)) + " at 542 nm and " + fmt("%.3f", blood_optical_density(b, 577)) +
                      " at 577 nm; about " + fmt("%.1f", b.total_uM_cm() / (150.0 / 64500.0 * 1e6) * 1e4) +
                      " um of whole blood.";
      if (model_.candidates.blood_excitation_path_factor != 0)
        s += " The excitation light is attenuated too (path factor " + fmt("%.2g", model_.candidates.blood_excitation_path_factor) + ").";
      return s;
    }
    case SpectraCause::kExtraFluorophore:
      return "A fluorophore missing from the model, " + extra_fluorophore_name(c) + ", makes on average " +
             pm(100 * d[0].value, 100 * d[0].uncertainty, "%.1f") + "% of the predicted signal.";
    case SpectraCause::kShift:
      return "The spectroradiometer's wavelength scale is off by " + pm(th[0], u[0], "%+.2f") +
             " nm (measured features sit at " + (th[0] >= 0 ? "longer" : "shorter") + " wavelengths than the model puts them).";
    case SpectraCause::kBandwidth:
      return "The measured spectra are blurred by an extra Gaussian of " + pm(th[0], u[0], "%.2f") +
             " nm FWHM beyond the stated instrument bandwidth.";
    case SpectraCause::kBroadening:
      return "The tissue's fluorescence bands are broader than the library's spectra: an extra Gaussian of " + pm(th[0], u[0], "%.2f") +
             " nm FWHM on the emission of every fluorophore (the filter edge stays sharp, so this is not the instrument).";
    case SpectraCause::kStray:
      return "A flat offset sits under every spectrum on the detector side (a dark level that was not subtracted, or stray "
             "light in the spectroradiometer), its level fitted per spectrum: on average " +
             pm(100 * d[0].value, 100 * d[0].uncertainty, "%.2f") + "% of the spectrum's recorded peak (" +
             fmt("%.2f", 100 * d[1].value) + "% of the tissue's mean signal, " + fmt("%.3g", d[2].value) + " in the data's units, " +
             fmt("%.1f", d[3].value) + " x the high-frequency noise).";
    case SpectraCause::kLeak:
      return "Excitation light leaks through the long-pass filter in its blocked band at an effective optical density of " +
             pm(d[0].value, d[0].uncertainty, "%.2f") + " (tissue reflectance included), " +
             fmt("%.2f", 100 * d[1].value) + "% of the signal on average" +
             (d.size() > 2 ? "; the light's own transmission through the passband adds " + fmt("%.2f", 100 * d[2].value) + "%." : ".");
    case SpectraCause::kEmissionShift:
      return "Every fluorophore's emission sits " + pm(th[0], u[0], "%+.2f") +
             " nm from the library's (fluorescence only; the filter edge and the leak stay where they are).";
    case SpectraCause::kFluorShift:
      return "The emission of " + cause_fluorophore(c) + " sits " + pm(th[0], u[0], "%+.2f") +
             " nm from the library's spectrum (bound +-15 nm).";
    case SpectraCause::kFluorWidth:
      return "The emission of " + cause_fluorophore(c) + " is broader than the library's: an extra Gaussian of " +
             pm(th[0], u[0], "%.1f") + " nm FWHM (bound 0-40 nm).";
    case SpectraCause::kFluorWidthEach: {
      std::string s = "Each fluorophore's emission is broadened by its own Gaussian (FWHM, bound 0-40 nm):";
      for (size_t k = 0; k < th.size(); ++k) s += " " + eem_names_[k] + " " + pm(th[k], u[k], "%.1f") + " nm;";
      return s;
    }
    case SpectraCause::kSecondBand:
      return "A second emission band of " + cause_fluorophore(c) + " at " + pm(th[0], u[0], "%.1f") + " nm, " +
             pm(th[1], u[1], "%.1f") + " nm FWHM, carrying " + pm(100 * th[2], 100 * u[2], "%.0f") +
             "% of the main band's energy (bounds: 25-100 nm beyond the main peak, 10-50 nm wide, 0-150 %).";
    case SpectraCause::kUnknownBand:
      return "An emission band that no library spectrum has: peak " + pm(th[0], u[0], "%.1f") + " nm, FWHM " +
             pm(th[1], u[1], "%.1f") + " nm, red/blue half-width ratio " + pm(th[2], u[2], "%.2f") +
             " (log-normal in wavenumber; 1 = Gaussian)" + (d.empty() ? std::string(".") : ", " + fmt("%.1f", 100 * d[0].value) + "% of the signal on average.");
    case SpectraCause::kResponse: {
      auto knots = response_knots(range_);
      std::string s = "The instrument's spectral responsivity differs from the one assumed by a smooth factor (an instrument "
                      "mismatch, not tissue):";
      for (size_t k = 0; k < th.size() && k < knots.size(); ++k)
        s += " " + fmt("%.0f", knots[k]) + " nm x" + fmt("%.3f", std::exp(th[k])) + ";";
      return s;
    }
    case SpectraCause::kLayered: {
      std::string s = "The tissue is a layered stack whose depth matters: the fluorophores it holds are excited and seen "
                      "through the blood at their depth, one parameter set per site for all excitations:";
      for (size_t q = 0; q < sites_.size() && 3 * q + 2 < th.size(); ++q) {
        auto v = layered_theta(&th[3 * q]);
        s += " " + sites_[q]->site() + ": epithelium " + pm(th[3 * q], u[3 * q], "%.3f") + " mm, blood " +
             pm(100 * th[3 * q + 1], 100 * u[3 * q + 1], "%.2f") + " % (oxy) + " + pm(100 * th[3 * q + 2], 100 * u[3 * q + 2], "%.2f") +
             " % (deoxy) by volume, saturation " + fmt("%.2f", v[2]) + ";";
      }
      return s;
    }
    case SpectraCause::kEdge: {
      double e = model_.emission_filter ? model_.emission_filter->edge_nm : 0;
      return "The long-pass filter edge is " + pm(th[0], u[0], "%+.2f") + " nm from where the model puts it (" + fmt("%.1f", e) +
             " -> " + fmt("%.1f", e + th[0]) + " nm), e.g. from the angle of incidence.";
    }
  }
  return c.title;
}

}  // namespace ofl
