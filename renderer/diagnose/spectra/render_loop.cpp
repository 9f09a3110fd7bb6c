#include "renderer/diagnose/spectra/render_loop.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <stdexcept>

#include "renderer/core/files/asset_path.h"
#include "renderer/core/files/json_node.h"
#include "renderer/diagnose/problem/model_extensions.h"
#include "renderer/numerics/nnls.h"
#include "renderer/render/render_job.h"

namespace ofl {

namespace {

bool is_instrument_column(const std::string& name) { return name == "leak" || name == "longpass_leak"; }

// Tissue causes travel with the rendered radiance; instrument causes are applied to it.
bool is_tissue_cause(const CandidateSpec& c) { return !c.instrument; }

}  // namespace

std::vector<double> render_item_patch(const SpectraProblem& p, int item, const nlohmann::json& material,
                                      const PatchRenderOptions& o) {
  const WavelengthGrid& g = p.grid();
  const SpectraModel& m = p.model();
  auto nm = p.abscissa(item);
  double lo = std::max(m.fit_min_nm, nm.front()) - o.margin_nm, hi = std::min(m.fit_max_nm, nm.back()) + o.margin_nm;
  nlohmann::json j = flat_patch_scene(material, g, p.excitation(p.light_of(item)), lo, hi, o);
  Scene scene = load_scene(JsonFile::from(j, "flat_patch(" + p.item_label(item) + ").json"));
  RenderOptions ro;
  ro.progress = false;
  ro.aovs = false;
  ro.fluorescence_layer = o.fluorescence_only;
  RenderResult r = render(scene, ro);
  std::vector<double> out(g.size(), 0.0);
  const SpectralImage& img = r.image;
  const size_t npx = size_t(img.width) * img.height;
  if (o.fluorescence_only && img.fluorescence.empty()) return out;  // no fluorophore: no fluorescence
  const std::vector<float>& v = o.fluorescence_only ? img.fluorescence : img.data;
  if (v.size() != npx * img.bands()) throw std::logic_error("render_item_patch: the render has no fluorescence layer");
  for (int b = 0; b < img.bands(); ++b) {
    int k = g.index_of(img.band_nm[b]);
    if (k < 0) continue;
    double s = 0;
    for (size_t q = 0; q < npx; ++q) s += v[q * img.bands() + b];
    out[k] = s / double(npx);
  }
  return out;
}

ItemFit compare_rendered(const SpectraProblem& p, const ModelState& instrument_state, int item,
                         const std::vector<double>& radiance) {
  SpectraProblem::Design d = p.instrument_design(instrument_state, item, radiance);
  Eigen::VectorXd y = p.measured(item);
  NnlsResult r = nnls(d.A, y);
  ItemFit f;
  f.measured = y;
  f.predicted = d.A * r.x;
  f.residual = y - f.predicted;
  f.local_dofs = r.active;
  f.locals["scale"] = r.x[0];
  return f;
}

ModelState instrument_only(const SpectraProblem& p, const ModelState& s) {
  ModelState out = s;
  out.causes.clear();
  for (auto& c : s.causes)
    if (!is_tissue_cause(p.candidates()[c.candidate])) out.causes.push_back(c);
  return out;
}

std::map<std::string, double> item_concentrations(const SpectraProblem& p, const ModelState& state, int item) {
  SpectraProblem::Design d = p.design(state, item);
  NnlsResult r = nnls(d.A, p.measured(item));
  std::map<std::string, double> c;
  for (size_t k = 0; k < d.names.size(); ++k)
    if (!is_instrument_column(d.names[k])) c[d.names[k]] = r.x[static_cast<Eigen::Index>(k)] * p.mean_radiance(item);
  return c;
}

std::map<std::string, double> joint_concentrations(const SpectraProblem& p, const ModelState& state,
                                                   const std::vector<int>& items, int iterations) {
  if (items.empty()) throw std::invalid_argument("joint_concentrations: no items");
  struct Split {
    Eigen::MatrixXd T, B;
    Eigen::VectorXd y;
  };
  std::vector<Split> parts;
  std::vector<std::string> tissue_names;
  for (int i : items) {
    SpectraProblem::Design d = p.design(state, i);
    std::vector<int> t, b;
    std::vector<std::string> names;
    for (size_t k = 0; k < d.names.size(); ++k) {
      if (is_instrument_column(d.names[k])) b.push_back(static_cast<int>(k));
      else { t.push_back(static_cast<int>(k)); names.push_back(d.names[k]); }
    }
    if (tissue_names.empty()) tissue_names = names;
    else if (names != tissue_names) throw std::logic_error("joint_concentrations: items with different columns");
    Split s;
    s.T.resize(d.A.rows(), static_cast<Eigen::Index>(t.size()));
    s.B.resize(d.A.rows(), static_cast<Eigen::Index>(b.size()));
    for (size_t k = 0; k < t.size(); ++k) s.T.col(static_cast<Eigen::Index>(k)) = d.A.col(t[k]);
    for (size_t k = 0; k < b.size(); ++k) s.B.col(static_cast<Eigen::Index>(k)) = d.A.col(b[k]);
    s.y = p.measured(i);
    parts.push_back(std::move(s));
  }
  const Eigen::Index K = static_cast<Eigen::Index>(tissue_names.size());
  const size_t M = items.size();
  // Start: the mean of the per-item fits in absolute units.
  Eigen::VectorXd c = Eigen::VectorXd::Zero(K);
  for (size_t q = 0; q < M; ++q) {
    Eigen::MatrixXd A(parts[q].T.rows(), K + parts[q].B.cols());
    A << parts[q].T, parts[q].B;
    NnlsResult r = nnls(A, parts[q].y);
    c += r.x.head(K) * p.mean_radiance(items[q]) / double(M);
  }
  std::vector<double> s(M, 0.0);
  std::vector<Eigen::VectorXd> a(M);
  long rows = 0;
  for (auto& pt : parts) rows += pt.y.size();
  for (int it = 0; it < iterations; ++it) {
    // Scale and leak amplitudes per item, for the current composition.
    for (size_t q = 0; q < M; ++q) {
      Eigen::MatrixXd A(parts[q].T.rows(), 1 + parts[q].B.cols());
      A.col(0) = parts[q].T * c;
      A.rightCols(parts[q].B.cols()) = parts[q].B;
      NnlsResult r = nnls(A, parts[q].y);
      s[q] = r.x[0];
      a[q] = r.x.tail(parts[q].B.cols());
    }
    // The composition, for these scales and leaks.
    Eigen::MatrixXd A(rows, K);
    Eigen::VectorXd b(rows);
    long row = 0;
    for (size_t q = 0; q < M; ++q) {
      const Eigen::Index n = parts[q].y.size();
      A.middleRows(row, n) = s[q] * parts[q].T;
      b.segment(row, n) = parts[q].y - parts[q].B * a[q];
      row += n;
    }
    NnlsResult r = nnls(A, b);
    if (r.x.sum() <= 0) break;
    c = r.x;
  }
  std::vector<double> abs_scale;
  for (size_t q = 0; q < M; ++q) {
    Eigen::MatrixXd A(parts[q].T.rows(), 1 + parts[q].B.cols());
    A.col(0) = parts[q].T * c;
    A.rightCols(parts[q].B.cols()) = parts[q].B;
    NnlsResult r = nnls(A, parts[q].y);
    if (r.x[0] > 0) abs_scale.push_back(r.x[0] * p.mean_radiance(items[q]));
  }
  if (!abs_scale.empty()) {
    std::nth_element(abs_scale.begin(), abs_scale.begin() + abs_scale.size() / 2, abs_scale.end());
    c *= abs_scale[abs_scale.size() / 2];
  }
  std::map<std::string, double> out;
  for (Eigen::Index k = 0; k < K; ++k) out[tissue_names[k]] = c[k];
  return out;
}

nlohmann::json state_report(const SpectraProblem& p, const ModelState& state, const std::vector<int>& items) {
  nlohmann::json causes = nlohmann::json::array();
  std::vector<ItemFit> fits;
  for (auto& a : state.causes) {
    const CandidateSpec& c = p.candidates()[a.candidate];
    nlohmann::json par = nlohmann::json::object();
    for (size_t k = 0; k < c.params.size(); ++k) par[c.params[k].name] = a.theta[k];
    if (spectra_cause(c) == SpectraCause::kExtraFluorophore) {
      if (fits.empty()) fits = p.evaluate(state, items);
      par["fluorophore"] = extra_fluorophore_name(c);
      for (auto& d : p.derived_params(c, fits, items)) par[d.name] = d.value;
    }
    causes.push_back({{"name", c.name}, {"id", c.id}, {"parameters", par}});
  }
  return {{"tool", "oralfluor diagnose (one cross-validation fold's global parameters)"},
          {"causes", causes},
          {"model_options", {{"blood_excitation_path_factor", p.model().candidates.blood_excitation_path_factor},
                             {"fit_range_nm", {p.model().fit_min_nm, p.model().fit_max_nm}},
                             {"fluorophores", p.model().fluorophores}}}};
}

void render_measurements(const SpectraProblem& tmpl, SpectraSet& set, const std::function<nlohmann::json(int)>& material,
                         const ModelState& instrument, const PatchRenderOptions& gen, double noise, uint64_t rng_seed) {
  std::mt19937_64 rng(rng_seed);
  std::normal_distribution<double> gauss;
  for (int i = 0; i < tmpl.num_items(); ++i) {
    PatchRenderOptions o = gen;
    o.seed = gen.seed + uint64_t(i);
    Eigen::VectorXd y = tmpl.instrument_design(instrument, i, render_item_patch(tmpl, i, material(i), o)).A.col(0);
    const double mean = y.mean();
    auto& sp = set.spectra[size_t(i)];
    if (!(mean > 0)) throw std::runtime_error("render_measurements: the render of " + tmpl.item_label(i) + " is dark");
    if (size_t(y.size()) != sp.nm.size()) throw std::logic_error("render_measurements: the set does not match the template");
    for (size_t k = 0; k < sp.nm.size(); ++k) {
      double v = y[Eigen::Index(k)];
      sp.value[k] = v + noise * std::sqrt(std::max(0.0, v) * mean) * gauss(rng);
    }
  }
}

Eigen::VectorXd modelled_spectrum(const SpectraProblem& p, const ModelState& state, int item,
                                  const std::map<std::string, double>& amounts) {
  SpectraProblem::Design d = p.design(state, item);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(d.A.rows());
  for (size_t k = 0; k < d.names.size(); ++k)
    if (auto a = amounts.find(d.names[k]); a != amounts.end())
      y += d.A.col(static_cast<Eigen::Index>(k)) * (a->second / p.mean_radiance(item));
  return y;
}

nlohmann::json fitted_material(const SpectraProblem& p, const ModelState& state, int item, const std::string& preset,
                               const std::map<std::string, double>& concentrations, const std::string& report_file) {
  const int site = p.site_of(item);
  for (auto& c : state.causes)
    if (spectra_cause(p.candidates()[c.candidate]) == SpectraCause::kLayered && site >= 0 && 3 * site + 2 < int(c.theta.size()))
      return p.layered_sites()[site]->material(layered_theta(&c.theta[3 * site]), true, concentrations);
  return tissue_material(preset, concentrations, report_file);
}

nlohmann::json tissue_material(const std::string& preset, const std::map<std::string, double>& concentrations,
                               const std::string& report_file) {
  nlohmann::json conc = nlohmann::json::object();
  // The preset's own fluorophores are zero unless fitted.
  JsonFile pf = JsonFile::load(asset_root() / "tissues" / (preset + ".json"));
  const nlohmann::json& mat = pf.doc().at("material");
  const nlohmann::json& layers = mat.contains("base") ? mat["base"]["fluorophores"] : mat["fluorophores"];
  for (auto& l : layers)
    if (l.contains("name")) conc[l["name"].get<std::string>()] = 0.0;
  for (auto& [k, v] : concentrations) conc[k] = v;
  nlohmann::json m = {{"type", "tissue"}, {"preset", preset}, {"coating", false}, {"concentrations", conc}};
  if (!report_file.empty()) m["diagnosis"] = report_file;
  return m;
}

double pooled_rmse(const std::vector<ItemFit>& fits, const std::vector<int>& items) {
  double ss = 0;
  long n = 0;
  for (int i : items) {
    ss += fits[i].residual.squaredNorm();
    n += fits[i].residual.size();
  }
  return n ? std::sqrt(ss / n) : 0.0;
}

}  // namespace ofl
