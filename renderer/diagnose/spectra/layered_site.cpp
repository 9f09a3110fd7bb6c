#include "renderer/diagnose/spectra/layered_site.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "renderer/core/files/asset_path.h"
#include "renderer/core/errors/error.h"
#include "renderer/diagnose/spectra/flat_patch.h"
#include "renderer/render/integrator/render_tables.h"
#include "renderer/render/stack/stack_response.h"
#include "renderer/scene/scene.h"

namespace ofl {

struct LayeredSite::Node {
  std::once_flag once;
  std::vector<float> log_f;  // [(k * lights + L) * coarse + c]
};

namespace {

constexpr uint64_t kSeed = 0x4C41594552534954ULL;  // one seed for every node: common random numbers

// The material's layers as a list of JSON objects (a preset's, then the material's own).
std::vector<nlohmann::json> named_layers(const nlohmann::json& material) {
  std::vector<nlohmann::json> out;
  if (material.contains("preset") && material["preset"].is_string()) {
    auto file = asset_root() / "tissues" / "layered" / (material["preset"].get<std::string>() + ".json");
    JsonFile pf = JsonFile::load(file);
    const nlohmann::json& m = pf.root().at("material").raw();
    if (m.contains("layers") && m["layers"].is_array())
      for (auto& l : m["layers"]) out.push_back(l);
  }
  if (material.contains("layers")) {
    const nlohmann::json& L = material["layers"];
    if (L.is_array())
      for (auto& l : L) out.push_back(l);
    else if (L.is_object())
      for (auto it = L.begin(); it != L.end(); ++it) {
        nlohmann::json l = it.value();
        l["name"] = it.key();
        out.push_back(l);
      }
  }
  return out;
}

// Merges `patch` into the layer called `name` of a material's "layers" (a list or a name-keyed object).
void patch_layer(nlohmann::json& material, const std::string& name, const nlohmann::json& patch) {
  nlohmann::json& L = material["layers"];
  if (L.is_array()) {
    for (auto& l : L)
      if (l.value("name", "") == name) {
        l.merge_patch(patch);
        return;
      }
    nlohmann::json l = patch;
    l["name"] = name;
    L.push_back(l);
    return;
  }
  if (!L.is_object()) L = nlohmann::json::object();
  L[name].merge_patch(patch);
}

// Index and weight of the interpolation cell of x in an increasing axis (clamped at the ends).
std::pair<int, double> cell(const std::vector<double>& axis, double x) {
  if (axis.size() < 2) return {0, 0.0};
  if (x <= axis.front()) return {0, 0.0};
  if (x >= axis.back()) return {int(axis.size()) - 2, 1.0};
  int k = int(std::upper_bound(axis.begin(), axis.end(), x) - axis.begin()) - 1;
  return {k, (x - axis[k]) / (axis[k + 1] - axis[k])};
}

WavelengthGrid coarse_grid(const WavelengthGrid& g, const LayeredCauseOptions& o) {
  const double step = o.transport_step_nm;
  const double a = o.min_nm > 0 ? std::max(o.min_nm, g.min_nm) : g.min_nm, b = o.max_nm > 0 ? std::min(o.max_nm, g.max_nm) : g.max_nm;
  double lo = std::floor(a / step) * step, hi = std::ceil(b / step) * step;
  return WavelengthGrid{std::max(lo, step), std::max(hi, lo + 2 * step), step};
}

}  // namespace

LayeredSite::LayeredSite(const LayeredSiteSpec& spec, const LayeredCauseOptions& opt, const WavelengthGrid& grid,
                         const std::vector<std::string>& names, const std::vector<GridEem>& eems,
                         const std::vector<std::vector<double>>& lights)
    : spec_(spec), opt_(opt), grid_(grid), names_(names), lights_(lights) {
  const std::string where = "/layered_tissue/sites/" + spec.site;
  for (auto* axis : {&opt_.thickness_mm, &opt_.blood_fraction, &opt_.saturation})
    if (axis->empty() || !std::is_sorted(axis->begin(), axis->end()))
      throw InputError(spec.source, where, "the parameter grids must be non-empty and increasing");
  for (auto& e : eems) {
    auto a = e.photon_albedo();
    a_peak_.push_back(*std::max_element(a.begin(), a.end()));
    absorb_.push_back(std::move(a));
  }
  // The layers (the preset's and the material's own): the fitted epithelium and the blood layers.
  // A preset that does not exist is left to the load below, which names it with the presets there are.
  std::vector<nlohmann::json> layers;
  try {
    layers = named_layers(spec.material);
  } catch (const InputError&) {
  }
  bool epithelium = false;
  for (auto& l : layers) {
    std::string n = l.value("name", "");
    if (n == opt_.epithelium) epithelium = true;
    if (l.contains("absorption") && l["absorption"].is_object() && l["absorption"].contains("blood") &&
        std::find(blood_layers_.begin(), blood_layers_.end(), n) == blood_layers_.end())
      blood_layers_.push_back(n);
  }
  if (!layers.empty() && !epithelium)
    throw InputError(spec.source, where, "the material has no layer named \"" + opt_.epithelium + "\" (the layer whose thickness is fitted)");
  if (!layers.empty() && blood_layers_.empty())
    throw InputError(spec.source, where, "no layer of the material holds blood (absorption.blood), so its blood cannot be fitted");
  // The material loads (this checks it, the preset name included) and holds which fluorophores.
  std::array<double, 3> mid = {opt_.thickness_mm[opt_.thickness_mm.size() / 2], opt_.blood_fraction[opt_.blood_fraction.size() / 2],
                               opt_.saturation[opt_.saturation.size() / 2]};
  held_.assign(names.size(), false);
  const WavelengthGrid cg = coarse_grid(grid_, opt_);
  Scene sc;
  try {
    sc = load_scene(JsonFile::from(flat_patch_scene(material(mid, false), cg, std::vector<double>(cg.size(), 1.0), cg.min_nm, cg.max_nm),
                                   spec.source + where));
  } catch (const InputError& e) {
    std::string at = e.field();
    const std::string prefix = "/materials/patch";
    if (at.rfind(prefix, 0) == 0) at = at.substr(prefix.size());
    throw InputError(spec.source, where,
                     "the layered_tissue material does not load" + (at.empty() ? std::string() : " (at " + at + ")") + ": " + e.what());
  }
  if (sc.materials.empty() || !sc.materials[0].stack.enabled) throw InputError(spec.source, where, "is not a layered_tissue material");
  if (layers.empty()) throw InputError(spec.source, where, "the material has no layers (give a preset or \"layers\")");
  for (auto& L : sc.materials[0].stack.layers)
    for (auto& f : L.fluorophores)
      for (size_t k = 0; k < names.size(); ++k)
        if (names[k] == f.name && a_peak_[k] > 0) held_[k] = true;
  nodes_.resize(opt_.thickness_mm.size() * opt_.blood_fraction.size() * opt_.saturation.size());
  for (auto& n : nodes_) n = std::make_unique<Node>();
}

LayeredSite::~LayeredSite() = default;

nlohmann::json LayeredSite::material(const std::array<double, 3>& theta, bool table_transport,
                                     const std::map<std::string, double>& amounts) const {
  nlohmann::json m = spec_.material;
  m["type"] = "layered_tissue";
  m["transport"] = table_transport ? "table" : "walk";
  patch_layer(m, opt_.epithelium, {{"thickness_mm", theta[0]}});
  for (auto& b : blood_layers_)
    patch_layer(m, b, {{"absorption", {{"blood", {{"volume_fraction", theta[1]}, {"saturation", theta[2]}}}}}});
  if (!amounts.empty())
    for (auto& l : named_layers(spec_.material)) {
      if (!l.contains("fluorophores") || !l["fluorophores"].is_array()) continue;
      nlohmann::json patch = nlohmann::json::object();
      for (auto& f : l["fluorophores"]) {
        auto a = amounts.find(f.value("name", ""));
        if (a != amounts.end() && f.contains("mua_per_mm") && f["mua_per_mm"].is_number())
          patch[a->first] = {{"mua_per_mm", f["mua_per_mm"].get<double>() * std::max(0.0, a->second)}};
      }
      if (!patch.empty()) patch_layer(m, l.value("name", ""), {{"fluorophores", patch}});
    }
  return m;
}

void LayeredSite::compute(Node& node, const std::array<double, 3>& theta) const {
  const WavelengthGrid cg = coarse_grid(grid_, opt_);
  Scene sc = load_scene(JsonFile::from(flat_patch_scene(material(theta, false), cg, std::vector<double>(cg.size(), 1.0), cg.min_nm, cg.max_nm),
                                       spec_.source + " layered_tissue " + spec_.site));
  RenderTables rt(sc);
  const MaterialTables& mt = rt.materials[0];
  const StackTables& st = mt.stack;
  StackResponseOptions so;
  so.photons = opt_.photons;
  so.seed = kSeed;
  const StackFluence fl = stack_fluence(st, mt, rt.n, {opt_.view_cos, opt_.light_cos}, so);
  const int B = fl.bins(), C = rt.n, K = int(names_.size()), NL = int(lights_.size());
  // Camera-side importance per bin, (n_a / n_l)^2 / dz.
  std::vector<double> cam(B);
  for (int b = 0; b < B; ++b) {
    double r = st.ambient_ior / st.layers[fl.layer[b]].ior;
    cam[b] = r * r / std::max(fl.hi[b] - fl.lo[b], 1e-12);
  }
  const auto& layers = sc.materials[0].stack.layers;
  node.log_f.assign(size_t(K) * NL * C, std::log(1e-30f));
  for (int k = 0; k < K; ++k) {
    if (!held_[k]) continue;
    // (mua QY) / a_peak of fluorophore k per layer.
    std::vector<double> s(layers.size(), 0.0);
    for (size_t l = 0; l < layers.size(); ++l)
      for (auto& f : layers[l].fluorophores)
        if (f.name == names_[k]) s[l] += f.mua_peak_per_mm * f.quantum_yield / a_peak_[k];
    for (int L = 0; L < NL; ++L) {
      // The light's absorbed photons on the coarse bins, and the fluence they make at each depth.
      std::vector<double> w(C, 0.0);
      double wsum = 0;
      for (int i = 0; i < grid_.size(); ++i) {
        double v = absorb_[k][i] * lights_[L][i] * grid_.wavelength(i);
        int c = cg.index_of(grid_.wavelength(i));
        if (v > 0 && c >= 0) { w[c] += v; wsum += v; }
      }
      if (!(wsum > 0)) continue;
      std::vector<double> x(B, 0.0);
      for (int c = 0; c < C; ++c) {
        if (w[c] == 0) continue;
        const double* ti = fl.at(1, c);
        for (int b = 0; b < B; ++b) x[b] += w[c] / wsum * ti[b];
      }
      for (int em = 0; em < C; ++em) {
        const double* to = fl.at(0, em);
        double f = 0;
        for (int b = 0; b < B; ++b) f += s[fl.layer[b]] * cam[b] * to[b] * x[b];
        node.log_f[(size_t(k) * NL + L) * C + em] = float(std::log(std::max(0.25 * f, 1e-30)));
      }
    }
  }
}

const LayeredSite::Node& LayeredSite::node(int it, int ib, int is) const {
  const size_t nb = opt_.blood_fraction.size(), ns = opt_.saturation.size();
  Node& n = *nodes_[(size_t(it) * nb + ib) * ns + is];
  std::call_once(n.once, [&] {
    auto t0 = std::chrono::steady_clock::now();
    compute(n, {opt_.thickness_mm[it], opt_.blood_fraction[ib], opt_.saturation[is]});
    node_ms_ += std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0).count();
    ++computed_;
  });
  return n;
}

std::vector<double> LayeredSite::factor(int k, int light, const std::array<double, 3>& theta) const {
  const WavelengthGrid cg = coarse_grid(grid_, opt_);
  const int C = cg.size(), NL = int(lights_.size());
  auto [it, tt] = cell(opt_.thickness_mm, theta[0]);
  auto [ib, tb] = cell(opt_.blood_fraction, theta[1]);
  auto [is, ts] = cell(opt_.saturation, theta[2]);
  const bool dt = opt_.thickness_mm.size() > 1, db = opt_.blood_fraction.size() > 1, ds = opt_.saturation.size() > 1;
  std::vector<double> lf(C, 0.0);
  for (int corner = 0; corner < 8; ++corner) {
    const int a = corner & 1, b = (corner >> 1) & 1, c = (corner >> 2) & 1;
    if ((a && !dt) || (b && !db) || (c && !ds)) continue;
    double wt = (a ? tt : (dt ? 1 - tt : 1)) * (b ? tb : (db ? 1 - tb : 1)) * (c ? ts : (ds ? 1 - ts : 1));
    if (wt == 0) continue;
    const Node& n = node(it + a, ib + b, is + c);
    const float* v = &n.log_f[(size_t(k) * NL + light) * C];
    for (int e = 0; e < C; ++e) lf[e] += wt * v[e];
  }
  std::vector<double> out(grid_.size());
  for (int i = 0; i < grid_.size(); ++i) {
    double x = (grid_.wavelength(i) - cg.min_nm) / cg.step_nm;
    int e = std::clamp(int(std::floor(x)), 0, C - 2);
    double t = std::clamp(x - e, 0.0, 1.0);
    out[i] = std::exp(lf[e]) * (1 - t) + std::exp(lf[e + 1]) * t;
  }
  return out;
}

LayeredCauseOptions parse_layered_cause(const JsonNode& n) {
  n.check_keys({"enabled", "site_column", "sites", "epithelium_layer", "transport_step_nm", "photons", "thickness_mm",
                "blood_fraction", "saturation"});
  LayeredCauseOptions o;
  o.enabled = n.boolean_or("enabled", true);
  if (auto c = n.find("site_column")) o.site_column = c->string();
  if (auto e = n.find("epithelium_layer")) o.epithelium = e->string();
  o.transport_step_nm = n.number_or("transport_step_nm", o.transport_step_nm, 1.0, 20.0);
  o.photons = n.integer_or("photons", o.photons, 100, 1000000);
  auto axis = [&](const char* key, std::vector<double>& v, double lo, double hi) {
    if (auto a = n.find(key)) {
      v = a->numbers();
      if (v.empty()) a->fail("needs at least one value");
      for (size_t i = 0; i < v.size(); ++i) {
        if (!(v[i] >= lo && v[i] <= hi)) a->fail("values must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
        if (i > 0 && !(v[i] > v[i - 1])) a->fail("values must increase");
      }
    }
  };
  axis("thickness_mm", o.thickness_mm, 0.001, 5.0);
  axis("blood_fraction", o.blood_fraction, 0.0, 1.0);
  axis("saturation", o.saturation, 0.0, 1.0);
  JsonNode S = n.at("sites");
  for (auto& site : S.keys()) {
    JsonNode m = S.at(site);
    LayeredSiteSpec spec;
    spec.site = site;
    spec.source = n.file();
    if (m.is_string()) spec.material = {{"preset", m.string()}};
    else if (m.is_object()) spec.material = m.raw();
    else m.fail("expected a layered preset name or a layered_tissue material object");
    o.sites.push_back(std::move(spec));
  }
  if (o.sites.empty()) S.fail("names no site");
  return o;
}

}  // namespace ofl
