// The spatial transport of layered tissue ("transport": "spatial", renderer/render/spatial/,
// docs/layered-tissue.md "Lateral transport"): light that enters at one point and leaves at another.
// - the elastic exit profiles it fills, against MCML's radial profiles (benchmarks/mcml_radial);
// - its fluorescence profile (excitation leg convolved with emission leg over depth), against an
//   independent forward photon Monte Carlo with positions;
// - a rendered lesion disc in healthy tissue, against a 3D forward Monte Carlo of the same geometry;
// - energy: under uniform light a flat patch renders as the position-free table does (which the
//   table's white furnace checks), for a real preset and for a non-absorbing stack on white;
// - the same image at any thread count; the profiles' cache; bad input.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "cli_runner.h"
#include "renderer/validation/harness/bench_check.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/mesh/files/gltf_writer.h"
#include "renderer/render/integrator/spatial_vertex.h"
#include "renderer/render/render_job.h"
#include "renderer/render/spatial/stack_profiles.h"
#include "renderer/render/stack/stack_response_cache.h"
#include "image_band_means.h"
#include "sanitizer_scale.h"

using namespace ofl;

namespace {

using nlohmann::json;

void expect_pass(const CheckCaseResult& r) {
  for (const auto& c : r.checks)
    EXPECT_TRUE(c.pass()) << r.name << ": " << c.quantity << ": " << c.value << " against " << c.reference << " +- " << c.tolerance;
}

json flat_scene(const json& material, int spp, int width = 48, double half_m = 0.05) {
  return {{"format", "oralfluor-scene"}, {"version", 1},
          {"integrator", {{"spp", spp}, {"seed", 3}, {"max_depth", 2},
                          {"wavelengths", {{"min_nm", 380}, {"max_nm", 700}, {"step_nm", 5}}},
                          {"output_bands", {{"min_nm", 385}, {"max_nm", 695}, {"step_nm", 10}}}}},
          {"camera", {{"position", {0, 0, 0.3}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 3}, {"resolution", {width, width}}}},
          {"materials", {{"t", material}}},
          {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {half_m, 0, 0}}, {"v", {0, half_m, 0}}, {"material", "t"}}}},
          {"lights", {{{"spd", {{"type", "sum"}, {"terms", {{{"type", "gaussian"}, {"peak_nm", 405}, {"fwhm_nm", 15}},
                                                               {{"type", "constant"}, {"value", 0.002}}}}}},
                       {"radiant_intensity_W_sr", 50.0}, {"profile", {{"half_angle_deg", 60}}},
                       {"position", {0.0, -1.0, 3.0}}, {"target", {0, 0, 0}}}}}};
}

// The relative standard deviation over pixels of the 400-700 nm band sum (on a uniformly lit patch,
// the image's Monte Carlo noise).
double pixel_noise(const SpectralImage& im) {
  const size_t px = size_t(im.width) * im.height;
  double s = 0, s2 = 0;
  for (size_t i = 0; i < px; ++i) {
    double v = 0;
    for (int b = 0; b < im.bands(); ++b)
      if (im.band_nm[b] >= 400 && im.band_nm[b] <= 700) v += im.data[i * im.bands() + b];
    s += v;
    s2 += v * v;
  }
  const double mu = s / px;
  return std::sqrt(std::max(0.0, s2 / px - mu * mu)) / mu;
}

// Spatial against table on the same uniformly lit flat patch, band by band: within 3 combined
// standard errors (the table's own per-pixel noise included) or 1.5 %.
void expect_same_as_table(json material, const char* what) {
  material["transport"] = "table";
  const Scene st = load_scene(JsonFile::from(flat_scene(material, test::sanitized_spp(32)), "flat_table.json"));
  material["transport"] = "spatial";
  material["profile_photons"] = 3000;  // energy does not depend on the profiles' noise: they are normalised
  const Scene ss = load_scene(JsonFile::from(flat_scene(material, test::sanitized_spp(64)), "flat_spatial.json"));
  RenderOptions o;
  o.progress = false;
  const RenderResult a = render(st, o), b = render(ss, o);
  const test::BandMeans ma = test::band_means(a.image, false), mb = test::band_means(b.image, false);
  int compared = 0;
  for (size_t i = 0; i < ma.mean.size(); ++i) {
    if (!(ma.mean[i] > 1e-3 * *std::max_element(ma.mean.begin(), ma.mean.end()))) continue;
    const double tol = std::max(0.015 * ma.mean[i], 3.0 * std::hypot(ma.se[i], mb.se[i]));
    EXPECT_NEAR(mb.mean[i], ma.mean[i], tol) << what << ", band " << a.image.band_nm[i] << " nm";
    ++compared;
  }
  EXPECT_GT(compared, 20) << what;
  // The anchor (docs/layered-tissue.md, "Lateral transport"): on one material under even light the
  // entry points' estimates cancel the anchor's, so a pixel is no noisier than the table's at the
  // same samples (here both scaled to one sample per pixel; 1.004x with the anchor).
  const double na = pixel_noise(a.image) * std::sqrt(double(st.integrator.spp)),
               nb = pixel_noise(b.image) * std::sqrt(double(ss.integrator.spp));
  std::printf("%s: per-pixel relative noise at 1 spp, table %.4f, spatial %.4f\n", what, na, nb);
  EXPECT_LT(nb, 1.1 * na) << what;  // without the anchor: 1.2x (lateral_tongue 1.253 against 1.034)
}

}  // namespace

TEST(LayeredSpatial, ElasticProfilesMatchMcmlRadialRuns) {
  for (const char* c : {"mucosa_405", "mucosa_450", "slab_n1.5", "keratinised_405"}) {
    const CheckCaseResult r = run_check_case(std::string("mcml_radial_") + c, test::kSanitized ? 40000 : 200000, 1);
    ASSERT_GE(r.checks.size(), 4u) << c;
    expect_pass(r);
  }
}

TEST(LayeredSpatial, FluorescenceProfileMatchesForwardPhotons) {
  const CheckCaseResult r = run_check_case("spatial_fluorescence_pencil", test::kSanitized ? 100000 : 400000, 1);
  ASSERT_GE(r.checks.size(), 10u);
  expect_pass(r);
  // The profile is far from position-free: under a third of the light leaves within 0.5 mm.
  double inner = 0;
  for (int i = 0; i < 7; ++i) inner += double(r.extra["spatial"]["shares"][i]);
  EXPECT_LT(inner, 0.33);
}

// The darker materials' crossing shares (darker_shares): for two materials the darker one's share d
// becomes d^gamma and the other's 1 - d^gamma, whichever index it has; for three, the cumulative
// shares from the darkest up are raised to gamma; shares still sum to one, a material without a share
// keeps none, and gamma = 1 changes nothing.
TEST(LayeredSpatial, DarkerSharesRaiseTheCumulativeShareOfTheDarker) {
  const double g = 0.8;
  double out[3];
  const double two[2] = {0.3, 0.7};
  const double dark_first[2] = {0.1, 0.5}, dark_second[2] = {0.5, 0.1};
  darker_shares(2, two, dark_first, g, out);
  EXPECT_NEAR(out[0], std::pow(0.3, g), 1e-12);
  EXPECT_NEAR(out[1], 1.0 - std::pow(0.3, g), 1e-12);
  darker_shares(2, two, dark_second, g, out);
  EXPECT_NEAR(out[1], std::pow(0.7, g), 1e-12);
  EXPECT_NEAR(out[0], 1.0 - std::pow(0.7, g), 1e-12);
  const double three[3] = {0.2, 0.5, 0.3}, refl[3] = {0.4, 0.6, 0.1};  // order: 2, 0, 1
  darker_shares(3, three, refl, g, out);
  EXPECT_NEAR(out[2], std::pow(0.3, g), 1e-12);
  EXPECT_NEAR(out[0], std::pow(0.5, g) - std::pow(0.3, g), 1e-12);
  EXPECT_NEAR(out[1], 1.0 - std::pow(0.5, g), 1e-12);
  EXPECT_NEAR(out[0] + out[1] + out[2], 1.0, 1e-12);
  const double with_zero[3] = {0.0, 0.6, 0.4}, zero_darkest[3] = {0.05, 0.3, 0.2};
  darker_shares(3, with_zero, zero_darkest, g, out);
  EXPECT_EQ(out[0], 0.0);
  EXPECT_NEAR(out[2], std::pow(0.4, g), 1e-12);
  EXPECT_NEAR(out[1], 1.0 - std::pow(0.4, g), 1e-12);
  darker_shares(3, three, refl, 1.0, out);
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(out[j], three[j], 1e-12);
}

TEST(LayeredSpatial, LesionDiscMatchesThreeDimensionalMonteCarlo) {
  for (const char* name : {"spatial_lesion_dysplasia_1mm", "spatial_lesion_dysplasia_1mm_fluorescence"}) {
    const CheckCaseResult r = run_check_case(name, test::kSanitized ? 200000 : 800000, 1);
    // 36 ring-band checks at 3 standard errors (2 % where larger): with both estimates right one
    // of them misses by chance in about one run of ten, so the test allows two misses of the 36
    // (p < 0.001 with all right) and none beyond 4 standard errors.
    int misses = 0;
    for (const auto& c : r.checks) {
      misses += !c.pass();
      EXPECT_LE(std::abs(c.value - c.reference), 4.0 / 3.0 * c.tolerance)
          << r.name << ": " << c.quantity << ": " << c.value << " against " << c.reference << " +- " << c.tolerance;
    }
    EXPECT_LE(misses, 2) << name;
    // The test can tell: the position-free profile misses the Monte Carlo's by far more somewhere.
    double worst = 0;
    const auto& pf = r.extra["position_free"]["contrast"];
    const auto& mc = r.extra["forward_mc"]["contrast"];
    for (size_t b = 0; b < pf.size(); ++b)
      for (size_t k = 0; k < pf[b].size(); ++k) worst = std::max(worst, std::abs(double(pf[b][k]) - double(mc[b][k])));
    EXPECT_GT(worst, 0.05) << name;
  }
}

// A blood spot's fluorescence: healthy tissue around it fluoresces, and the light it sends into the
// spot is dimmed by the spot's blood on the way (docs/layered-tissue.md, "Regions and lateral
// transport"). Inside the disc (rings within 0.85 of its radius), per band, the mean of the rendered
// contrast over those rings agrees with the 3D Monte Carlo's within 3 combined standard errors of
// the mean (or 2 %). Taking both legs from the emission point's material alone put the inner rings
// 0.11-0.19 above the Monte Carlo, about 4 standard errors of this mean at these samples.
TEST(LayeredSpatial, BloodSpotDimsTheFluorescenceThatCrossesIt) {
  const CheckCaseResult r =
      run_check_case("spatial_lesion_blood_spot_1mm_fluorescence", test::kSanitized ? 400000 : 1600000, 1);
  const auto& edges = r.extra["ring_edges_mm"];
  const auto& sp = r.extra["spatial"];
  const auto& mc = r.extra["forward_mc"];
  ASSERT_GT(edges.size(), 4u);
  for (size_t b = 0; b < sp["contrast"].size(); ++b) {
    double diff = 0, var = 0, ref = 0;
    int n = 0;
    for (size_t k = 0; k + 1 < edges.size() && double(edges[k + 1]) <= 0.85 + 1e-9; ++k, ++n) {
      diff += double(sp["contrast"][b][k]) - double(mc["contrast"][b][k]);
      ref += double(mc["contrast"][b][k]);
      const double s1 = sp["se"][b][k], s2 = mc["se"][b][k];
      var += s1 * s1 + s2 * s2;
    }
    ASSERT_GE(n, 2);
    const double tol = std::max(3.0 * std::sqrt(var) / n, 0.02 * ref / n);
    EXPECT_LE(std::abs(diff / n), tol) << "band " << b << ": spatial - Monte Carlo inside the disc " << diff / n;
    // And the spot is still darker than the healthy tissue it is in, as the Monte Carlo says.
    EXPECT_LT(double(sp["contrast"][b][0]), 0.9) << "band " << b;
  }
}

// The vertical passage a path crossing regions makes at each end (docs/layered-tissue.md, "Regions
// and lateral transport") is the depth over which the two stacks differ. `blood_spot` is
// `lateral_tongue` with blood in its 0.2 mm superficial stroma (the presets' files); a stack against
// itself differs nowhere; one whose epithelium alone is changed differs over its thickness; one whose semi-infinite layer starts 0.45 mm down differs from there to
// the 1 mm the passage is counted to.
TEST(LayeredSpatial, PassageIsTheDepthOverWhichTwoStacksDiffer) {
  auto preset = [](const char* name) {
    const Scene sc = load_scene(JsonFile::from(flat_scene({{"type", "layered_tissue"}, {"preset", name}}, 1, 4), "p.json"));
    return sc.materials[0].stack;
  };
  const LayerStack healthy = preset("lateral_tongue"), blood = preset("blood_spot");
  EXPECT_NEAR(differing_depth_mm(healthy, blood), 0.20, 1e-9);
  EXPECT_NEAR(differing_depth_mm(blood, healthy), 0.20, 1e-9);
  EXPECT_EQ(differing_depth_mm(healthy, healthy), 0.0);
  // The epithelium (under the thin wet coating) alone changed.
  LayerStack epi = healthy;
  ASSERT_GE(epi.layers.size(), 4u);
  ASSERT_EQ(epi.layers[1].name, "epithelium");
  epi.layers[1].g = 0.8;
  EXPECT_NEAR(differing_depth_mm(healthy, epi), healthy.layers[1].thickness_mm, 1e-9);
  LayerStack deep = healthy;
  deep.layers.back().g = 0.8;
  double above = 0;
  for (size_t i = 0; i + 1 < healthy.layers.size(); ++i) above += healthy.layers[i].thickness_mm;
  EXPECT_NEAR(differing_depth_mm(healthy, deep), kPassageMm - above, 1e-9);
}

TEST(LayeredSpatial, UniformLightRendersAsThePositionFreeTable) {
  expect_same_as_table({{"type", "layered_tissue"}, {"preset", "lateral_tongue"}}, "lateral_tongue");
  // A non-absorbing scattering layer on a white base: everything that enters comes back out.
  expect_same_as_table({{"type", "layered_tissue"},
                        {"coating", {{"ior", 1.33}, {"roughness", 0.2}, {"thickness_mm", 0.01}}},
                        {"layers", {{{"name", "clear"}, {"thickness_mm", 1.0}, {"ior", 1.4},
                                     {"scattering", {{"g", 0.8}, {"mus_per_mm", 5.0}}}}}},
                        {"bottom", {{"type", "base"}, {"reflectance", 1.0}}}},
                       "white furnace stack");
}

TEST(LayeredSpatial, SameImageAtAnyThreadCount) {
  const json m = {{"type", "layered_tissue"}, {"preset", "dysplasia"}, {"transport", "spatial"}, {"profile_photons", 1000}};
  const Scene sc = load_scene(JsonFile::from(flat_scene(m, 2, 24), "threads.json"));
  RenderOptions o;
  o.progress = false;
  std::vector<float> first;
  for (int threads : {1, 2, 3}) {
    tbb::global_control g(tbb::global_control::max_allowed_parallelism, threads);
    const RenderResult r = render(sc, o);
    if (first.empty()) first = r.image.data;
    else EXPECT_EQ(0, std::memcmp(first.data(), r.image.data.data(), 4 * first.size())) << threads << " threads";
  }
}

TEST(LayeredSpatial, ProfilesAreCachedBitForBit) {
  const json m = {{"type", "layered_tissue"}, {"preset", "lateral_tongue"}, {"transport", "spatial"}, {"profile_photons", 200}};
  const Scene sc = load_scene(JsonFile::from(flat_scene(m, 1, 4), "cache.json"));
  RenderTables t(sc);
  const StackTables& st = t.materials[0].stack;
  StackProfileOptions o;
  o.photons = 200;
  o.cache_dir = test::fresh_dir("profile_cache");
  auto fresh = build_stack_profiles(st, t.materials[0], t.n, o);
  EXPECT_FALSE(fresh->from_cache);
  EXPECT_TRUE(std::filesystem::exists(stack_cache_file(o.cache_dir, stack_profile_key(st, t.materials[0], t.n, o), kProfileEntry)));
  auto again = build_stack_profiles(st, t.materials[0], t.n, o);
  EXPECT_TRUE(again->from_cache);
  EXPECT_EQ(fresh->elastic_mass, again->elastic_mass);
  EXPECT_EQ(fresh->leg_mass, again->leg_mass);
  EXPECT_EQ(fresh->fine_fluence, again->fine_fluence);
  StackProfileOptions o2 = o;
  o2.photons += 1;
  EXPECT_NE(stack_profile_key(st, t.materials[0], t.n, o2), stack_profile_key(st, t.materials[0], t.n, o));
  std::filesystem::remove_all(o.cache_dir);
}

TEST(LayeredSpatial, BadInputIsRefusedOrWarned) {
  const json spatial = {{"type", "layered_tissue"}, {"preset", "lateral_tongue"}, {"transport", "spatial"}, {"profile_photons", 1000}};
  const json table = {{"type", "layered_tissue"}, {"preset", "dysplasia"}};
  const auto dir = test::fresh_dir("spatial_bad");
  // A regions material mixing the spatial transport with another: named, refused.
  json j = flat_scene(spatial, 1, 4);
  j["materials"] = {{"healthy", spatial}, {"lesion", table},
                    {"t", {{"type", "regions"}, {"base", "healthy"},
                           {"regions", {{{"sphere", {{"center_m", {0, 0, 0}}, {"radius_mm", 1.0}}}, {"material", "lesion"}}}}}}};
  try {
    load_scene(JsonFile::from(j, "mixed.json"));
    ADD_FAILURE() << "mixed transports accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"healthy\" uses the \"spatial\" transport but \"lesion\" does not"), std::string::npos) << e.what();
    EXPECT_NE(e.describe().find("/materials/t/regions/0/material"), std::string::npos) << e.describe();
  }
  // Lateral profiles asked of a transport without them; a sphere of radius 0; a mask and a sphere.
  json k = table;
  k["profile_photons"] = 1000;
  EXPECT_THROW(load_scene(JsonFile::from(flat_scene(k, 1, 4), "photons.json")), InputError);
  json z = j;
  z["materials"]["lesion"] = spatial;
  z["materials"]["t"]["regions"][0]["sphere"]["radius_mm"] = 0.0;
  EXPECT_THROW(load_scene(JsonFile::from(z, "zero.json")), InputError);
  z["materials"]["t"]["regions"][0]["sphere"]["radius_mm"] = 1.0;
  z["materials"]["t"]["regions"][0]["mask"] = "mask.png";
  EXPECT_THROW(load_scene(JsonFile::from(z, "both.json")), InputError);
  // A mesh thinner than the light's sideways travel (a 20 x 20 x 0.3 mm box): a warning naming it.
  TriangleMesh box;
  box.name = "thin_box";
  box.material = "tissue";
  const float h = 0.01f, d = 0.00015f;
  for (float z0 : {d, -d})
    for (auto [x, y] : std::vector<std::pair<float, float>>{{-h, -h}, {h, -h}, {h, h}, {-h, h}}) box.positions.push_back({x, y, z0});
  box.indices = {0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6, 0, 4, 5, 0, 5, 1, 1, 5, 6, 1, 6, 2, 2, 6, 7, 2, 7, 3, 3, 7, 4, 3, 4, 0};
  GlbDocument doc;
  doc.meshes = {box};
  write_glb(dir / "box.glb", doc);
  json b = flat_scene(spatial, 1, 8);
  b["geometry"] = {{{"type", "gltf"}, {"file", (dir / "box.glb").string()}, {"materials", {{"tissue", "t"}}}}};
  RenderOptions o;
  o.progress = false;
  const RenderResult r = render(load_scene(JsonFile::from(b, "box.json")), o);
  bool warned = false;
  for (const auto& w : r.stats.warnings) warned = warned || (w.find("thin_box") != std::string::npos && w.find("thinner than") != std::string::npos);
  EXPECT_TRUE(warned);
  std::filesystem::remove_all(dir);
}
