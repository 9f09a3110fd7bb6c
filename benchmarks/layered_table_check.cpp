// How far the tabulated stack response (transport "table") is from the random walk it replaces
// (transport "walk", the reference), per layered preset, on the 350-750 nm / 5 nm grid under a
// 405 nm LED (fluorescence) and a flat white LED (reflection):
// - the table's build time and walks;
// - for a few (viewing, light) cosine pairs: the next-event fluorescence summed over 480-700 nm and
//   the diffuse (non-specular) next-event reflection at 450, 550 and 630 nm, table against the walk
//   averaged over the light's azimuth, and the walk at light azimuths 0, 90 and 180 degrees from
//   the viewer's (what the azimuth average gives up);
// - the directional diffuse reflectance (continuation weights) at the same wavelengths.
//   usage: layered_table_check [--samples N] [--photons N] [--similarity N] [--presets a,b,...]
// (--similarity sets the material's table_similarity_after; 0 = the exact phase in the fill)
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/core/files/json_node.h"
#include "renderer/render/integrator/layered_bsdf.h"
#include "renderer/render/render_job.h"
#include "renderer/render/stack/stack_response.h"
#include "tests/layered_table_bench.h"

using namespace ofl;
using nlohmann::json;

namespace {

using test::Bench;
using test::Mean;
using test::direction;

int g_similarity = -1;

std::unique_ptr<Bench> bench(const std::string& preset, const char* transport, int photons) {
  json m = {{"type", "layered_tissue"}, {"preset", preset}, {"transport", transport}};
  if (photons > 0) m["table_photons"] = photons;
  if (g_similarity >= 0) m["table_similarity_after"] = g_similarity;
  json j = {{"format", "oralfluor-scene"}, {"version", 1},
            {"integrator", {{"wavelengths", {{"min_nm", 350}, {"max_nm", 750}, {"step_nm", 5}}},
                            {"output_bands", {{"min_nm", 370}, {"max_nm", 720}, {"step_nm", 10}}}}},
            {"camera", {{"position", {0, 0, 1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 10}, {"resolution", {4, 4}}}},
            {"materials", {{"m", m}}},
            {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {1, 0, 0}}, {"v", {0, 1, 0}}, {"material", "m"}}}},
            {"lights", {{{"spd", {{"type", "gaussian"}, {"peak_nm", 405}, {"fwhm_nm", 15}}}, {"radiant_intensity_W_sr", 1.0},
                         {"position", {0, 0, 10}}, {"target", {0, 0, 0}}},
                        {{"spd", 1.0}, {"radiant_intensity_W_sr", 1.0}, {"position", {0, 0.1, 10}}, {"target", {0, 0, 0}}}}}};
  auto b = std::make_unique<Bench>();
  b->scene = load_scene(JsonFile::from(j, preset + ".json"));
  b->tables = std::make_unique<RenderTables>(b->scene);
  return b;
}

std::string pm(const Mean& m) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g +- %.2g", m.mean(), m.se());
  return buf;
}

void init_lanes(PathLanes& p, const std::vector<int>& bins) {
  for (int k = 0; k < kLanes; ++k) {
    p.film[k] = p.wl[k] = bins[k];
    p.beta[k] = 1;
    p.L[k] = p.Lf[k] = 0;
    p.fl[k] = p.rerad_prev[k] = false;
  }
}

// The walk's next-event fluorescence (sum of lanes) under LED group 0 and diffuse reflection per
// lane under group 1 (the top's specular lobe subtracted: the same closed form in both transports);
// phi < 0: the light's azimuth uniformly random.
void walk_nee(const Bench& b, const std::vector<int>& fl_bins, const std::vector<int>& el_bins, double mu_o, double mu_i,
              double phi, long long samples, Mean& fluo, std::vector<Mean>& refl) {
  const MaterialTables& mt = b.mt();
  const glm::dvec3 wo = direction(mu_o, 0.0);
  refl.assign(el_bins.size(), Mean());
  for (long long s = 0; s < samples; ++s) {
    Rng rng(9, Rng::stream_for(uint64_t(mu_o * 1000 + mu_i * 10), uint64_t(s)));
    LightSample ls;
    ls.valid = true;
    ls.g = 1.0;
    ls.wi = direction(mu_i, phi < 0 ? 2.0 * kPi * rng.next_double() : phi);
    PathLanes p;
    ls.group = 0;
    init_lanes(p, fl_bins);
    layered_scatter(mt, StackPointFactors(), wo, ls, b.tables->light_shape, b.tables->n, p, rng);
    double f = 0;
    for (int k = 0; k < kLanes; ++k) f += p.Lf[k];
    fluo.add(f);
    ls.group = 1;
    init_lanes(p, el_bins);
    layered_scatter(mt, StackPointFactors(), wo, ls, b.tables->light_shape, b.tables->n, p, rng);
    const double fs = mt.stack.top.smooth() ? 0.0 : mt.stack.top.reflection(wo, ls.wi);
    for (size_t k = 0; k < el_bins.size(); ++k)
      refl[k].add(p.L[k] - p.Lf[k] - fs * b.tables->light_shape[1][el_bins[k]]);
  }
}

// The walk's directional diffuse reflectance (elastic continuation weights, top reflection excluded).
std::vector<Mean> walk_albedo(const Bench& b, const std::vector<int>& bins, double mu_o, long long samples) {
  std::vector<Mean> out(bins.size());
  for (long long s = 0; s < samples; ++s) {
    Rng rng(10, Rng::stream_for(uint64_t(mu_o * 1000), uint64_t(s)));
    PathLanes p;
    init_lanes(p, bins);
    LayeredScatter c = layered_scatter(b.mt(), StackPointFactors(), direction(mu_o, 0), LightSample(), b.tables->light_shape,
                                       b.tables->n, p, rng);
    for (size_t k = 0; k < bins.size(); ++k) out[k].add(c.ok && !c.reflected && !p.fl[k] ? p.beta[k] : 0.0);
  }
  return out;
}

double table_albedo(const StackResponse& r, double mu_o, int wl) {
  const StackResponse::Weights a = r.weights(mu_o);
  double s = 0;
  const int steps = 4000;
  for (int j = 0; j < steps; ++j) {
    double mu = (j + 0.5) / steps;
    s += r.elastic_at(a, r.weights(mu), wl) * mu;
  }
  return 2.0 * kPi * s / steps;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string t; std::getline(ss, t, ',');) out.push_back(t);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  long long samples = 4000;
  int photons = 0;
  std::vector<std::string> presets = {"lateral_tongue", "dorsal_tongue", "buccal_mucosa", "dysplasia", "blood_spot"};
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--samples" && i + 1 < argc) samples = std::stoll(argv[++i]);
    else if (a == "--photons" && i + 1 < argc) photons = std::stoi(argv[++i]);
    else if (a == "--similarity" && i + 1 < argc) g_similarity = std::stoi(argv[++i]);
    else if (a == "--presets" && i + 1 < argc) presets = split(argv[++i]);
  }
  const std::pair<double, double> dirs[] = {{0.9, 0.7}, {0.5, 0.85}, {0.3, 0.5}};
  for (const auto& name : presets) {
    auto walk = bench(name, "walk", 0);
    auto table = bench(name, "table", photons);
    const StackResponse& r = *table->mt().stack.response;
    const WavelengthGrid& g = walk->scene.grid();
    std::vector<int> fl_bins, el_bins;
    for (int k = 0; k < kLanes; ++k) fl_bins.push_back(g.index_of(480 + 220.0 * (k + 0.5) / kLanes));
    for (double nm : {450.0, 550.0, 630.0}) el_bins.push_back(g.index_of(nm));
    while (int(el_bins.size()) < kLanes) el_bins.push_back(el_bins.back());
    std::printf("%s: table %lld walks in %.2f s\n", name.c_str(), r.walks, r.build_seconds);
    // LED light entering through a rough top: the forward sampling the table uses (scatter() from
    // outside) against the walk's next-event connection (transmit(), the other side's BTDF).
    if (!table->mt().stack.top.smooth())
      for (double mu : {0.9, 0.7, 0.5, 0.3}) {
        const DielectricInterface& top = table->mt().stack.top;
        Rng rng(4, uint64_t(mu * 100));
        const glm::dvec3 down = -direction(mu, 0.0);
        double fwd = 0, nee = 0;
        const int m = 200000;
        for (int j = 0; j < m; ++j) {
          InterfaceEvent e = top.scatter(down, rng);
          if (e.transmitted) fwd += e.weight;
          InterfaceEvent t = top.transmit(down, rng.next_double(), rng.next_double());
          if (t.weight > 0 && t.dir.z < 0) nee += t.weight;
        }
        std::printf("  top transmittance at mu %.1f: scatter() %.4f, transmit() %.4f (ratio %.3f)\n", mu, fwd / m, nee / m,
                    fwd / nee);
      }
    for (auto [mu_o, mu_i] : dirs) {
      const StackResponse::Weights a = r.weights(mu_o), b = r.weights(mu_i);
      double tf = 0;
      for (int k = 0; k < kLanes; ++k) tf += r.direct_at(0, a, b, fl_bins[k]);
      Mean wf;
      std::vector<Mean> wr;
      walk_nee(*walk, fl_bins, el_bins, mu_o, mu_i, -1, samples, wf, wr);
      std::printf("  mu_o %.2f mu_i %.2f fluorescence 480-700: table %.4g, walk (azimuth average) %s (table/walk %.3f)\n", mu_o,
                  mu_i, tf, pm(wf).c_str(), tf / wf.mean());
      for (size_t k = 0; k < 3; ++k) {
        double te = r.elastic_at(a, b, el_bins[k]) * table->tables->light_shape[1][el_bins[k]];
        std::printf("    diffuse reflection %.0f nm: table %.4g, walk (azimuth average) %s (table/walk %.3f)\n",
                    g.wavelength(el_bins[k]), te, pm(wr[k]).c_str(), te / wr[k].mean());
      }
      for (double deg : {0.0, 90.0, 180.0}) {
        Mean af;
        std::vector<Mean> ar;
        walk_nee(*walk, fl_bins, el_bins, mu_o, mu_i, deg * kPi / 180.0, samples / 2, af, ar);
        std::printf("    light azimuth %3.0f deg: walk fluorescence %s (/ average %.3f); diffuse 450 %s (%.3f) 550 %s (%.3f) 630 %s (%.3f)\n",
                    deg, pm(af).c_str(), af.mean() / wf.mean(), pm(ar[0]).c_str(), ar[0].mean() / wr[0].mean(),
                    pm(ar[1]).c_str(), ar[1].mean() / wr[1].mean(), pm(ar[2]).c_str(), ar[2].mean() / wr[2].mean());
      }
    }
    for (double mu_o : {0.9, 0.5, 0.2}) {
      auto wa = walk_albedo(*walk, el_bins, mu_o, samples);
      std::printf("  directional diffuse reflectance at mu_o %.1f:", mu_o);
      for (size_t k = 0; k < 3; ++k)
        std::printf("  %.0f nm table %.4f walk %s", g.wavelength(el_bins[k]), table_albedo(r, mu_o, el_bins[k]), pm(wa[k]).c_str());
      std::printf("\n");
    }
  }
  return 0;
}
