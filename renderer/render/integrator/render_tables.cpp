#include "renderer/render/integrator/render_tables.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "renderer/camera/description/camera_description.h"
#include "renderer/camera/sensor/expected_signal.h"
#include "renderer/core/errors/error.h"
#include "renderer/render/spatial/spatial_tables.h"
#include "renderer/render/spatial/stack_profiles.h"
#include "renderer/render/stack/stack_response.h"
#include "renderer/render/stack/stack_response_cache.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {

namespace {

// The lateral profiles of a spatial stack and what the renderer looks up from them.
void build_spatial(const Scene& sc, const LayerStack& stack, const std::string& name, int used, RenderTables& rt,
                   MaterialTables& t) {
  StackProfileOptions o;
  if (stack.profile_photons > 0) o.photons = stack.profile_photons;
  if (stack.table_similarity_after == 0) o.similarity_after = 0;  // exact phase asked for: profiles too
  o.used_bins = used;
  o.cache_dir = default_stack_cache_dir();
  o.label = name;
  auto prof = build_stack_profiles(t.stack, t, rt.n, o);
  for (const std::string& w : prof->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  t.stack.spatial = build_spatial_stack(t.stack, prof, rt.light_shape);
}

// Layered materials with transport "table" or "spatial": their response, for the bins camera lanes
// can reach (up to the last bin the film samples; re-radiation only moves a lane to shorter
// wavelengths); for "spatial" also the lateral profiles.
void build_stack_responses(const Scene& sc, RenderTables& rt) {
  int used = 0;
  for (int i = 0; i < rt.n; ++i)
    if (rt.wavelength_pdf.pmf[i] > 0) used = i + 1;
  for (size_t k = 0; k < rt.materials.size(); ++k) {
    MaterialTables& t = rt.materials[k];
    const LayerStack& stack = sc.materials[k].stack;
    if (!t.stack.enabled || stack.transport == StackTransport::kWalk || stack.transport == StackTransport::kVolume) continue;
    if (std::string why = stack_response_unsupported(t.stack, t); !why.empty()) {
      if (stack.transport == StackTransport::kSpatial)
        throw InputError(sc.file, "/materials/" + sc.materials[k].name + "/transport",
                         "\"spatial\" needs the stack's table, but " + why + "; use \"walk\"");
      continue;
    }
    StackResponseOptions o;
    if (stack.table_photons > 0) o.photons = stack.table_photons;
    o.used_bins = used;
    o.cache_dir = default_stack_cache_dir();
    if (stack.table_similarity_after >= 0) o.similarity_after = stack.table_similarity_after;
    o.label = sc.materials[k].name;
    auto r = build_stack_response(t.stack, t, rt.n, rt.light_shape, o);
    for (const std::string& w : r->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    t.stack.response = std::move(r);
    if (stack.transport == StackTransport::kSpatial) build_spatial(sc, stack, sc.materials[k].name, used, rt, t);
  }
}

// The LEDs' spectra grouped by shape (one photon shape per group, each LED's scale and group) and
// the choice of a light by power.
void group_light_spectra(const Scene& sc, RenderTables& rt) {
  const int n = rt.n;
  int groups = 0;
  std::vector<int> group_of_first(sc.lights.size(), -1);
  for (size_t i = 0; i < sc.lights.size(); ++i) {
    int g = sc.lights[i].spd_group;
    if (group_of_first[g] < 0) {
      group_of_first[g] = groups++;
      std::vector<float> shape(n, 0.0f);
      double i0 = sc.lights[i].intensity_W_sr;
      for (int k = 0; k < n; ++k) shape[k] = i0 > 0 ? float(sc.lights[i].spectral_photons[k] / i0) : 0.0f;
      rt.light_shape.push_back(std::move(shape));
    }
    rt.light_group.push_back(group_of_first[g]);
    rt.light_scale.push_back(float(sc.lights[i].intensity_W_sr));
  }
  std::vector<double> power;
  for (auto& l : sc.lights) power.push_back(l.power_W);
  rt.light_select = DiscreteDistribution(power);
}

// A material's layer transmission at grid bin k on the way out and on the way in (1 without a layer).
double transmission_out(const Material& m, int k) { return m.layer_out.empty() ? 1.0 : m.layer_out[k]; }
double transmission_in(const Material& m, int k) { return m.layer_in.empty() ? 1.0 : m.layer_in[k]; }

// One fluorophore of material m: its re-emission table and its direct response to each LED group's
// spectrum.
FluorophoreTables fluorophore_tables(const Scene& sc, const RenderTables& rt, const Material& m, const FluorophoreLayer& f) {
  const int n = rt.n;
  const double step = rt.grid.step_nm;
  FluorophoreTables ft;
  ft.texture = f.texture;
  ft.texture_offset = float(f.texture_offset);
  ft.texture_scale = float(f.texture_scale);
  ft.concentration = float(f.concentration);
  const GridEem& e = sc.eems[f.eem];
  tabulate_reemission(
      n, [&](int em, int ex) { return e.at(em, ex) * step * transmission_out(m, em) * transmission_in(m, ex); }, ft.phi,
      ft.row_sum, ft.row_cdf);
  for (const auto& shape : rt.light_shape) {
    std::vector<float> d(n, 0.0f);
    for (int em = 0; em < n; ++em) {
      double s = 0;
      for (int ex = 0; ex < em; ++ex) s += double(ft.phi[size_t(em) * n + ex]) * shape[ex];
      d[em] = float(s);
    }
    ft.direct.push_back(std::move(d));
  }
  return ft;
}

// A material's render-time tables: reflectance and emission on the grid, the coating's lobes, the
// fluorophores' tables and the layered stack's.
MaterialTables material_tables(const Scene& sc, const RenderTables& rt, const Material& m) {
  const int n = rt.n;
  const bool fluo = sc.integrator.fluorescence;
  MaterialTables t;
  t.reflectance.resize(n);
  for (int k = 0; k < n; ++k) t.reflectance[k] = float(m.reflectance[k] * transmission_out(m, k) * transmission_in(m, k));
  if (!m.emission.empty()) {
    t.emission.resize(n);
    for (int k = 0; k < n; ++k) t.emission[k] = float(m.emission[k] * photons_per_joule(rt.grid.wavelength(k)));
  }
  t.reflectance_texture = m.reflectance_texture;
  t.coated = m.coating.enabled;
  if (t.coated) {
    t.coating.prepare(m.coating.ior, m.coating.roughness);
    double reg = sc.integrator.regularize_glossy;
    if (reg > m.coating.roughness) t.coating_regularized.prepare(m.coating.ior, reg);
    else t.coating_regularized = t.coating;
  }
  if (fluo)
    for (const auto& f : m.fluorophores)
      if (f.concentration > 0) t.fluorophores.push_back(fluorophore_tables(sc, rt, m, f));
  t.stack = build_stack_tables(m.stack, sc.eems, rt.light_shape, fluo);
  return t;
}

// The output bands' weights per grid bin, and the wavelength sampling: uniform over the bins that
// reach a band, half of it moved by importance (the given weights, else the importance camera's
// summed QE) so that every band keeps a floor of samples; the film's scale per bin follows.
void bands_and_wavelengths(const Scene& sc, const std::vector<double>& importance, RenderTables& rt) {
  const int n = rt.n;
  const WavelengthGrid& grid = rt.grid;
  const BandSet& bs = sc.integrator.bands;
  rt.bands = bs.size();
  rt.band_weights.assign(n, {});
  std::vector<double> useful(n, 0.0);
  std::vector<double> camera_weight;
  if (importance.empty() && !sc.integrator.importance_camera.empty()) {
    CameraDescription cam = load_camera(sc.integrator.importance_camera);
    camera_weight.assign(n, 0.0);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) camera_weight[i] += system_qe(cam, c, grid.wavelength(i), 0.0, 0.0);
  }
  for (int i = 0; i < n; ++i) {
    for (int b = 0; b < rt.bands; ++b) {
      double lo = std::max(grid.bin_lo(i), bs.centre(b) - 0.5 * bs.step_nm);
      double hi = std::min(grid.bin_hi(i), bs.centre(b) + 0.5 * bs.step_nm);
      if (hi - lo > 1e-9) rt.band_weights[i].push_back({b, float((hi - lo) / bs.step_nm)});
    }
    useful[i] = rt.band_weights[i].empty() ? 0.0 : 1.0;
  }
  const std::vector<double>& imp = importance.empty() ? camera_weight : importance;
  if (!imp.empty()) {
    double su = 0, si = 0;
    for (int i = 0; i < n; ++i) { su += useful[i]; si += useful[i] * imp[i]; }
    if (si > 0)
      for (int i = 0; i < n; ++i) useful[i] = useful[i] * (0.5 / su + 0.5 * imp[i] / si);
  }
  rt.wavelength_pdf = DiscreteDistribution(useful);
  rt.film_scale.assign(n, 0.0);
  for (int i = 0; i < n; ++i)
    if (rt.wavelength_pdf.pmf[i] > 0) rt.film_scale[i] = photon_energy_J(grid.wavelength(i)) / rt.wavelength_pdf.pmf[i];
}

}  // namespace

RenderTables::RenderTables(const Scene& sc, const std::vector<double>& importance) : n(sc.grid().size()), grid(sc.grid()) {
  group_light_spectra(sc, *this);
  for (const Material& m : sc.materials) materials.push_back(material_tables(sc, *this, m));
  bands_and_wavelengths(sc, importance, *this);
  build_stack_responses(sc, *this);
}

}  // namespace ofl
