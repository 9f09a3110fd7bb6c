// The tabulated stack response (transport "table", renderer/render/stack/stack_response.h) against the
// random walk it was filled from (transport "walk", the reference), and against conservation laws:
// - for two presets, the directional diffuse reflectance (elastic part of the continuation) and
//   the next-event fluorescence (summed over the emission lanes, per LED) at a viewing and a light
//   direction that fall between the table's nodes, the walk averaged over the light's azimuth;
// - a white furnace (non-absorbing stack over a white base) through the table: sampling and
//   evaluating the table returns exactly what enters, nothing is created;
// - reciprocity of the elastic part under a smooth top: f(o, i) against f(i, o), with the spread
//   between two independently seeded tables as the noise scale;
// - the on-disk cache: an entry read back is the fresh fill bit for bit; what the fill reads changes
//   the key; corrupt, cut-short and unwritable entries cost a warning and a fresh fill.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "renderer/core/files/json_node.h"
#include "renderer/render/integrator/layered_bsdf.h"
#include "renderer/render/render_job.h"
#include "renderer/render/stack/stack_response.h"
#include "renderer/render/stack/stack_response_cache.h"
#include "layered_table_bench.h"

using namespace ofl;

namespace {

using nlohmann::json;

using test::Bench;
using test::Mean;
using test::direction;

std::unique_ptr<Bench> bench(json material, const char* transport, int photons = 0) {
  material["transport"] = transport;
  if (photons > 0) material["table_photons"] = photons;
  json j = {{"format", "oralfluor-scene"}, {"version", 1},
            {"integrator", {{"wavelengths", {{"min_nm", 380}, {"max_nm", 700}, {"step_nm", 10}}},
                            {"output_bands", {{"min_nm", 390}, {"max_nm", 690}, {"step_nm", 10}}}}},
            {"camera", {{"position", {0, 0, 1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 10}, {"resolution", {4, 4}}}},
            {"materials", {{"m", material}}},
            {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {1, 0, 0}}, {"v", {0, 1, 0}}, {"material", "m"}}}},
            {"lights", {{{"spd", {{"type", "gaussian"}, {"peak_nm", 405}, {"fwhm_nm", 15}}}, {"radiant_intensity_W_sr", 1.0},
                         {"position", {0, 0, 10}}, {"target", {0, 0, 0}}}}}};
  auto b = std::make_unique<Bench>();
  b->scene = load_scene(JsonFile::from(j, "layered_table_test.json"));
  b->tables = std::make_unique<RenderTables>(b->scene);
  return b;
}

json preset(const char* name) { return {{"type", "layered_tissue"}, {"preset", name}}; }

// What one vertex evaluation gives: the fluorescence next-event estimate summed over the lanes,
// and per lane the elastic diffuse continuation weight (lanes that left through the stack, not
// the top's reflection, and were not re-radiated).
struct Estimates {
  Mean fluo;
  std::vector<Mean> diffuse;
};

template <class Scatter>
Estimates estimate(const Bench& b, const std::vector<int>& bins, double mu_o, double mu_i, long long samples, uint64_t seed,
                   Scatter scatter) {
  Estimates e;
  e.diffuse.resize(bins.size());
  const glm::dvec3 wo = direction(mu_o, 0.0);
  for (long long s = 0; s < samples; ++s) {
    Rng rng(seed, Rng::stream_for(77, uint64_t(s)));
    LightSample ls;
    ls.valid = true;
    ls.group = 0;
    ls.g = 1.0;
    ls.wi = direction(mu_i, 2.0 * kPi * rng.next_double());  // averaged over the light's azimuth
    PathLanes p;
    for (int k = 0; k < kLanes; ++k) {
      p.film[k] = p.wl[k] = bins[k % bins.size()];
      p.beta[k] = 1;
      p.L[k] = p.Lf[k] = 0;
      p.fl[k] = p.rerad_prev[k] = false;
    }
    LayeredScatter c = scatter(ls, wo, p, rng);
    double f = 0;
    for (int k = 0; k < kLanes; ++k) f += p.Lf[k];
    e.fluo.add(f);
    for (size_t k = 0; k < bins.size(); ++k)
      e.diffuse[k].add(c.ok && !c.reflected && !p.fl[k] && p.wl[k] == bins[k] ? p.beta[k] : 0.0);
  }
  return e;
}

// The table's directional diffuse reflectance at cosine mu_o, by sampling its continuation (the
// part that is not the top lobe; table mode chooses the lobe before the lanes choose their event,
// so the elastic part of a cosine-lobe sample is counted through its evaluation instead).
double table_diffuse_albedo(const Bench& b, double mu_o, int wl) {
  const StackResponse& r = *b.mt().stack.response;
  const StackResponse::Weights a = r.weights(mu_o);
  const int steps = 4000;
  double s = 0;
  for (int j = 0; j < steps; ++j) {
    double mu = (j + 0.5) / steps;
    s += r.elastic_at(a, r.weights(mu), wl) * mu;
  }
  return 2.0 * kPi * s / steps;
}

void compare_preset(const char* name) {
  auto walk = bench(preset(name), "walk");
  auto table = bench(preset(name), "table", 1500);
  ASSERT_FALSE(walk->mt().stack.response);
  ASSERT_TRUE(table->mt().stack.response);
  // Emission lanes over 460-690 nm for the fluorescence; the reflectance from the same walks.
  const std::vector<int> bins = {walk->bin(460), walk->bin(490), walk->bin(520), walk->bin(550),
                                 walk->bin(580), walk->bin(610), walk->bin(640), walk->bin(680)};
  const double mu_o = 0.77, mu_i = 0.62;  // between nodes
  const long long samples = 2000;
  Estimates w = estimate(*walk, bins, mu_o, mu_i, samples, 5, [&](const LightSample& ls, const glm::dvec3& wo, PathLanes& p, Rng& rng) {
    return layered_scatter(walk->mt(), StackPointFactors(), wo, ls, walk->tables->light_shape, walk->tables->n, p, rng);
  });
  // The table's fluorescence: deterministic given the directions (its next-event term has no randomness).
  const StackResponse& r = *table->mt().stack.response;
  const StackResponse::Weights a = r.weights(mu_o), bw = r.weights(mu_i);
  double fluo_table = 0;
  for (int k = 0; k < kLanes; ++k) fluo_table += r.direct_at(0, a, bw, bins[k]);
  const double fw = w.fluo.mean(), fse = w.fluo.se();
  std::printf("%s: fluorescence next-event (sum of 8 lanes) walk %.5g +- %.2g, table %.5g (%.2f %%)\n", name, fw, fse, fluo_table,
              100 * (fluo_table / fw - 1));
  EXPECT_NEAR(fluo_table, fw, std::max(0.02 * fw, 3 * fse)) << name;
  for (size_t k = 0; k < bins.size(); ++k) {
    double t = table_diffuse_albedo(*table, mu_o, bins[k]);
    double m = w.diffuse[k].mean(), se = w.diffuse[k].se();
    std::printf("%s: diffuse reflectance at %.0f nm walk %.4f +- %.4f, table %.4f (%.2f %%)\n", name,
                walk->scene.grid().wavelength(bins[k]), m, se, t, 100 * (t / m - 1));
    EXPECT_NEAR(t, m, std::max(0.02 * m, 3 * se)) << name << " bin " << bins[k];
  }
}

}  // namespace

TEST(LayeredTable, AgreesWithTheWalkLateralTongue) { compare_preset("lateral_tongue"); }

TEST(LayeredTable, AgreesWithTheWalkBloodSpot) { compare_preset("blood_spot"); }

TEST(LayeredTable, WhiteFurnaceReturnsWhatEnters) {
  // Non-absorbing layers with index steps over a white base under a rough wet film (layered_furnace).
  auto layer = [](const char* name, double d, double n, double mus, double g) {
    return json{{"name", name}, {"thickness_mm", d}, {"ior", n}, {"scattering", {{"g", g}, {"mus_per_mm", mus}}}};
  };
  json m = {{"type", "layered_tissue"},
            {"coating", {{"ior", 1.33}, {"roughness", 0.25}, {"thickness_mm", 0.01}}},
            {"layers", {layer("keratin", 0.03, 1.5, 20.0, 0.9), layer("epithelium", 0.2, 1.37, 5.0, 0.8),
                        layer("stroma", 0.5, 1.4, 10.0, 0.9)}},
            {"bottom", {{"type", "base"}, {"reflectance", 1.0}}}};
  auto b = bench(m, "table", 3000);
  ASSERT_TRUE(b->mt().stack.response);
  const int wl = b->bin(550);
  for (double mu_o : {0.15, 0.5, 0.9}) {
    // Everything the vertex returns, through the path tracer's own sampling of the table.
    Mean albedo;
    for (int s = 0; s < 40000; ++s) {
      Rng rng(3, Rng::stream_for(uint64_t(mu_o * 100), uint64_t(s)));
      PathLanes p;
      for (int k = 0; k < kLanes; ++k) {
        p.film[k] = p.wl[k] = wl;
        p.beta[k] = 1;
        p.L[k] = p.Lf[k] = 0;
        p.fl[k] = p.rerad_prev[k] = false;
      }
      LayeredScatter c = layered_table_scatter(b->mt(), direction(mu_o, 0), LightSample(), b->tables->light_shape, p, rng);
      albedo.add(c.ok ? p.beta[0] : 0.0);
    }
    std::printf("furnace mu_o %.2f: albedo through the table %.4f +- %.4f\n", mu_o, albedo.mean(), albedo.se());
    EXPECT_NEAR(albedo.mean(), 1.0, std::max(0.01, 3 * albedo.se())) << mu_o;
  }
}

TEST(LayeredTable, ElasticPartIsReciprocal) {
  // A smooth top: the rough top's lossless resampling is not reciprocal (stack_response.h).
  json m = preset("lateral_tongue");
  m["coating"] = false;
  auto b = bench(m, "walk");
  const StackTables& st = b->mt().stack;
  StackResponseOptions o;
  o.photons = 1000;
  auto t1 = build_stack_response(st, b->mt(), b->tables->n, b->tables->light_shape, o);
  o.seed += 1;
  auto t2 = build_stack_response(st, b->mt(), b->tables->n, b->tables->light_shape, o);
  // Over wavelengths 450-650 nm (less noise), for every pair of nodes.
  const int lo = b->bin(450), hi = b->bin(650), N = t1->nodes;
  auto band = [&](const StackResponse& r, int o_, int i_) {
    double s = 0;
    for (int wl = lo; wl <= hi; ++wl) s += r.elastic[r.cell(o_, i_) * r.n + wl];
    return s;
  };
  double rec = 0, noise = 0, scale = 0;
  int pairs = 0;
  for (int i = 0; i < N; ++i)
    for (int j = i + 1; j < N; ++j) {
      double a = band(*t1, i, j), at = band(*t1, j, i), a2 = band(*t2, i, j);
      rec += (a - at) * (a - at);
      noise += (a - a2) * (a - a2);
      scale += a * a;
      ++pairs;
    }
  rec = std::sqrt(rec / pairs);
  noise = std::sqrt(noise / pairs);
  scale = std::sqrt(scale / pairs);
  std::printf("reciprocity: rms f(o,i) - f(i,o) %.3g, rms between two seeds %.3g, rms f %.3g\n", rec, noise, scale);
  // Reciprocal: the transpose differs from the table only by noise (an unreciprocal table, e.g. one
  // missing a cosine, differs by tens of percent of f).
  EXPECT_LT(rec, 1.5 * noise + 0.002 * scale);
  EXPECT_GT(scale, 0);
}

namespace {

std::filesystem::path fresh_dir(const char* name) {
  auto d = std::filesystem::temp_directory_path() / ("ofl_stack_cache_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(d);
  return d;
}

void expect_same_table(const StackResponse& a, const StackResponse& b) {
  ASSERT_EQ(a.elastic.size(), b.elastic.size());
  ASSERT_EQ(a.fluor.size(), b.fluor.size());
  EXPECT_EQ(0, std::memcmp(a.elastic.data(), b.elastic.data(), 4 * a.elastic.size()));
  EXPECT_EQ(0, std::memcmp(a.fluor.data(), b.fluor.data(), 4 * a.fluor.size()));
  EXPECT_EQ(a.fluor_sum, b.fluor_sum);
  EXPECT_EQ(a.direct, b.direct);
}

}  // namespace

TEST(LayeredTable, CacheGivesTheFreshTableAndRefusesStaleOrCorruptEntries) {
  auto b = bench(preset("lateral_tongue"), "walk");
  const StackTables& st = b->mt().stack;
  StackResponseOptions o;
  o.photons = 150;
  auto fresh = build_stack_response(st, b->mt(), b->tables->n, b->tables->light_shape, o);
  EXPECT_FALSE(fresh->from_cache);
  EXPECT_GT(fresh->elastic_albedo(6, b->bin(600)), 0.05);

  o.cache_dir = fresh_dir("a");
  auto first = build_stack_response(st, b->mt(), b->tables->n, b->tables->light_shape, o);
  EXPECT_FALSE(first->from_cache);
  EXPECT_TRUE(first->warnings.empty());
  const std::string key = stack_response_key(st, b->mt(), b->tables->n, o);
  const auto file = stack_cache_file(o.cache_dir, key);
  ASSERT_TRUE(std::filesystem::exists(file));
  auto second = build_stack_response(st, b->mt(), b->tables->n, b->tables->light_shape, o);
  EXPECT_TRUE(second->from_cache);
  expect_same_table(*fresh, *second);  // bit for bit, LED sums recomputed from the same light shapes
  EXPECT_EQ(second->walks, fresh->walks);

  // Anything the fill reads changes the key: an option, a layer's thickness, a scattering value.
  StackResponseOptions o2 = o;
  o2.seed += 1;
  EXPECT_NE(stack_response_key(st, b->mt(), b->tables->n, o2), key);
  StackTables thicker = st;
  thicker.layers[0].bottom += 0.01;
  EXPECT_NE(stack_response_key(thicker, b->mt(), b->tables->n, o), key);
  StackTables cloudier = st;
  cloudier.layers.back().mus[3] *= 1.0001f;
  EXPECT_NE(stack_response_key(cloudier, b->mt(), b->tables->n, o), key);

  // A corrupt entry (one byte flipped) is ignored with a warning naming it, filled again, overwritten.
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(200);
    char c = 0;
    f.read(&c, 1);
    c ^= 0x10;
    f.seekp(200);
    f.write(&c, 1);
  }
  auto third = build_stack_response(st, b->mt(), b->tables->n, b->tables->light_shape, o);
  EXPECT_FALSE(third->from_cache);
  ASSERT_EQ(third->warnings.size(), 1u);
  EXPECT_NE(third->warnings[0].find(file.string()), std::string::npos) << third->warnings[0];
  expect_same_table(*fresh, *third);
  EXPECT_TRUE(build_stack_response(st, b->mt(), b->tables->n, b->tables->light_shape, o)->from_cache);
  // Cut short: ignored too.
  std::filesystem::resize_file(file, 1000);
  EXPECT_FALSE(build_stack_response(st, b->mt(), b->tables->n, b->tables->light_shape, o)->from_cache);
  std::filesystem::remove_all(o.cache_dir);

  // A cache that cannot be written (a file where its folder should be) costs a warning, not the table.
  o.cache_dir = fresh_dir("b");
  { std::ofstream(o.cache_dir.string()) << "x"; }
  auto unwritable = build_stack_response(st, b->mt(), b->tables->n, b->tables->light_shape, o);
  EXPECT_FALSE(unwritable->from_cache);
  ASSERT_EQ(unwritable->warnings.size(), 1u);
  EXPECT_NE(unwritable->warnings[0].find("not cached"), std::string::npos) << unwritable->warnings[0];
  expect_same_table(*fresh, *unwritable);
  std::filesystem::remove(o.cache_dir);
}
