// The volume walk of layered tissue ("transport": "volume", renderer/render/integrator/layered_bsdf.h,
// docs/layered-tissue.md "The volume walk"): the walk keeps its lateral position and runs in the
// material under it, crossing from one `regions` material into another.
// - crossing into an identical material changes nothing: the image equals the position-free walk's
//   within its noise (reflected light and fluorescence, whose sub-walks cross too);
// - energy: two different non-absorbing stacks on a white base, side by side under a uniform sky,
//   reflect everything at every pixel, also where the walks cross between them (white furnace);
// - the texture coordinates the region look-up extrapolates along the surface (closed form);
// - the same image at any thread count; bad input named.
// Against the 3D forward Monte Carlo of a lesion disc: `oralfluor bench volume_lesion_*`
// (benchmarks/results.d/41_spatial.md; too slow for the suite at a useful precision).
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/image/texture.h"
#include "renderer/scene/scene.h"
#include "renderer/render/render_job.h"
#include "renderer/render/trace/embree_scene.h"
#include "renderer/render/trace/rng.h"
#include "image_band_means.h"
#include "sanitizer_scale.h"

using namespace ofl;

namespace {

using nlohmann::json;

// A flat patch seen from above under one LED (violet plus a little white), `material` on a quad
// of half-width 25 mm.
json patch_scene(const json& materials, const std::string& material, int spp, int width) {
  return {{"format", "oralfluor-scene"}, {"version", 1},
          {"integrator", {{"spp", spp}, {"seed", 5}, {"max_depth", 1},
                          {"wavelengths", {{"min_nm", 380}, {"max_nm", 700}, {"step_nm", 5}}},
                          {"output_bands", {{"min_nm", 400}, {"max_nm", 680}, {"step_nm", 40}}}}},
          {"camera", {{"position", {0, 0, 0.3}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 1.5}, {"resolution", {width, width}}}},
          {"materials", materials},
          {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.05, 0, 0}}, {"v", {0, 0.05, 0}}, {"material", material}}}},
          {"lights", {{{"spd", {{"type", "sum"}, {"terms", {{{"type", "gaussian"}, {"peak_nm", 405}, {"fwhm_nm", 15}},
                                                               {{"type", "constant"}, {"value", 0.01}}}}}},
                       {"radiant_intensity_W_sr", 50.0}, {"profile", {{"half_angle_deg", 60}}},
                       {"position", {0.0, -1.0, 3.0}}, {"target", {0, 0, 0}}}}}};
}

// Discs of `inside` in `outside` (spheres cutting the patch), all with transport "volume": the view
// (7.9 mm wide) holds three edges within the walks' reach.
json discs(const json& outside, const json& inside) {
  json o = outside, i = inside;
  o["transport"] = "volume";
  i["transport"] = "volume";
  json regions = json::array();
  for (const auto& c : {std::array<double, 3>{0.0008, 0.0, 0.0005}, std::array<double, 3>{-0.0012, 0.0009, 0.0004},
                        std::array<double, 3>{0.0, -0.0013, 0.0003}})
    regions.push_back({{"sphere", {{"center_m", {c[0], c[1], 0.0}}, {"radius_mm", 1000.0 * c[2]}}}, {"material", "inside"}});
  return {{"outside", o}, {"inside", i}, {"t", {{"type", "regions"}, {"base", "outside"}, {"regions", regions}}}};
}

RenderResult render_quiet(const json& j, const char* name) {
  const Scene sc = load_scene(JsonFile::from(j, name));
  RenderOptions o;
  o.progress = false;
  return render(sc, o);
}

}  // namespace

// The walk stops at every crossing and goes on in the other material's stack with a fresh flight
// (exponential flights have no memory): across identical materials the expected image is the
// position-free walk's exactly, for reflected light and for fluorescence.
TEST(LayeredVolume, CrossingIntoTheSameMaterialChangesNothing) {
  const json tongue = {{"type", "layered_tissue"}, {"preset", "lateral_tongue"}};
  json walk = tongue;
  walk["transport"] = "walk";
  const int spp = test::sanitized_spp(6), w = 24;
  const RenderResult a = render_quiet(patch_scene({{"t", walk}}, "t", spp, w), "walk.json");
  const RenderResult b = render_quiet(patch_scene(discs(tongue, tongue), "t", spp, w), "volume.json");
  for (bool fl : {false, true}) {
    const test::BandMeans ma = test::band_means(a.image, fl), mb = test::band_means(b.image, fl);
    int compared = 0;
    for (size_t i = 0; i < ma.mean.size(); ++i) {
      if (!(ma.mean[i] > 0.02 * *std::max_element(ma.mean.begin(), ma.mean.end()))) continue;
      EXPECT_NEAR(mb.mean[i], ma.mean[i], 3.5 * std::hypot(ma.se[i], mb.se[i]))
          << (fl ? "fluorescence" : "all light") << ", band " << a.image.band_nm[i] << " nm";
      ++compared;
    }
    EXPECT_GE(compared, 4) << (fl ? "fluorescence" : "all light");
  }
}

// Two different non-absorbing stacks over a white base (same depth, same indices), discs of one in
// the other, inside a sky of radiance 1: all light that enters comes back out, so every pixel is 1,
// next to the edges too, where the walks cross from one stack into the other.
TEST(LayeredVolume, WhiteFurnaceAcrossRegions) {
  const json coat = {{"ior", 1.33}, {"roughness", 0.2}, {"thickness_mm", 0.01}};
  const json white = {{"type", "base"}, {"reflectance", 1.0}};
  const json a = {{"type", "layered_tissue"}, {"coating", coat}, {"bottom", white},
                  {"layers", {{{"name", "one"}, {"thickness_mm", 1.0}, {"ior", 1.4}, {"scattering", {{"g", 0.8}, {"mus_per_mm", 5.0}}}}}}};
  const json b = {{"type", "layered_tissue"}, {"coating", coat}, {"bottom", white},
                  {"layers", {{{"name", "dense"}, {"thickness_mm", 0.3}, {"ior", 1.4}, {"scattering", {{"g", 0.0}, {"mus_per_mm", 30.0}}}},
                              {{"name", "loose"}, {"thickness_mm", 0.7}, {"ior", 1.4}, {"scattering", {{"g", 0.9}, {"mus_per_mm", 2.0}}}}}}};
  json mats = discs(a, b);
  mats["sky"] = {{"type", "lambertian"}, {"reflectance", 0.0}, {"emission", 1.0}};
  json j = patch_scene(mats, "t", test::sanitized_spp(8), 48);
  j["lights"] = json::array();
  j["geometry"].push_back({{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 100}, {"material", "sky"}});
  j["integrator"]["wavelengths"] = {{"min_nm", 400}, {"max_nm", 700}, {"step_nm", 10}};
  j["integrator"]["output_bands"] = {{"min_nm", 450}, {"max_nm", 650}, {"step_nm", 100}};
  const RenderResult r = render_quiet(j, "furnace.json");
  const SpectralImage& im = r.image;
  // Whole image, and the pixels within 0.3 mm of the first disc's edge (0.5 mm around (0.8, 0) mm).
  double s = 0, s2 = 0, e = 0, e2 = 0;
  int n = 0, ne = 0;
  const double half_mm = 300.0 * std::tan(0.75 * 3.14159265358979 / 180.0);
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      double v = 0;
      for (int k = 0; k < im.bands(); ++k) v += im.pixel(x, y)[k] / im.bands();
      s += v;
      s2 += v * v;
      ++n;
      const double X = (2.0 * (x + 0.5) / im.width - 1.0) * half_mm, Y = (1.0 - 2.0 * (y + 0.5) / im.height) * half_mm;
      if (std::abs(std::hypot(X - 0.8, Y) - 0.5) < 0.3) {
        e += v;
        e2 += v * v;
        ++ne;
      }
    }
  const double mean = s / n, se = std::sqrt((s2 / n - mean * mean) / (n - 1));
  const double edge = e / ne, se_edge = std::sqrt((e2 / ne - edge * edge) / (ne - 1));
  std::printf("furnace across regions: mean %.4f +- %.4f, near an edge %.4f +- %.4f (%d pixels)\n", mean, se, edge, se_edge, ne);
  EXPECT_GT(ne, 50);
  EXPECT_NEAR(mean, 1.0, std::max(0.01, 3.0 * se));
  EXPECT_NEAR(edge, 1.0, std::max(0.015, 3.0 * se_edge));
}

// The region look-up steps along the surface from the hit point: the texture coordinates' gradient
// of a quad of 40 x 20 mm is (1 / 0.04 m, 0) and (0, 1 / 0.02 m), whatever the hit.
TEST(LayeredVolume, UvGradientOfAQuadIsItsInverseSize) {
  json j = patch_scene({{"t", {{"type", "lambertian"}, {"reflectance", 0.5}}}}, "t", 1, 4);
  j["geometry"][0]["u"] = {0.04, 0, 0};
  j["geometry"][0]["v"] = {0, 0.02, 0};
  const Scene sc = load_scene(JsonFile::from(j, "quad.json"));
  const EmbreeScene es(sc);
  for (const auto& o : {glm::dvec3(0.003, -0.002, 1.0), glm::dvec3(-0.011, 0.006, 1.0)}) {
    const RayHit h = es.intersect(o, glm::dvec3(0, 0, -1));
    ASSERT_TRUE(h.found());
    const UvGradient g = es.uv_gradient(h);
    // (mesh positions are floats: a relative 1e-6)
    EXPECT_NEAR(std::abs(g.u.x), 25.0, 25e-6);
    EXPECT_NEAR(g.u.y, 0.0, 25e-6);
    EXPECT_NEAR(std::abs(g.v.y), 50.0, 50e-6);
    EXPECT_NEAR(g.v.x, 0.0, 50e-6);
    // Stepping along the gradient reproduces the texture coordinates of a second hit.
    const SurfacePoint a = es.surface(h, o, glm::dvec3(0, 0, -1));
    const glm::dvec3 o2 = o + glm::dvec3(0.002, 0.001, 0);
    const RayHit h2 = es.intersect(o2, glm::dvec3(0, 0, -1));
    const SurfacePoint b = es.surface(h2, o2, glm::dvec3(0, 0, -1));
    EXPECT_NEAR(b.uv.x, a.uv.x + glm::dot(g.u, b.p - a.p), 1e-5);
    EXPECT_NEAR(b.uv.y, a.uv.y + glm::dot(g.v, b.p - a.p), 1e-5);
  }
}

// The clearance the walk skips region reads within: the distance to the nearest sphere of the
// regions material (closed form), infinite without regions, 0 where a texture mask decides and no texture coordinates are given (see MaskClearanceBoundsWhereTheRegionEnds); and
// within it resolve_material's answer indeed does not change.
TEST(LayeredVolume, RegionClearanceIsTheDistanceToTheNearestSphere) {
  const json mats = discs({{"type", "layered_tissue"}, {"preset", "lateral_tongue"}}, {{"type", "layered_tissue"}, {"preset", "blood_spot"}});
  const Scene sc = load_scene(JsonFile::from(patch_scene(mats, "t", 1, 4), "clearance.json"));
  int regions = -1, plain = -1;
  for (size_t m = 0; m < sc.materials.size(); ++m) (sc.materials[m].dispatches() ? regions : plain) = int(m);
  ASSERT_GE(regions, 0);
  ASSERT_GE(plain, 0);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(region_clearance_m(sc, plain, glm::dvec3(0.0)), inf);
  // Spheres (centre x, y, radius in m) as discs() places them, all at z = 0.
  const double sph[3][3] = {{0.0008, 0.0, 0.0005}, {-0.0012, 0.0009, 0.0004}, {0.0, -0.0013, 0.0003}};
  Rng rng(11, 0);
  for (int i = 0; i < 200; ++i) {
    const glm::dvec3 p(0.006 * rng.next_double() - 0.003, 0.006 * rng.next_double() - 0.003, 0.0);
    double want = inf;
    for (const auto& c : sph) want = std::min(want, std::abs(std::hypot(p.x - c[0], p.y - c[1]) - c[2]));
    const double got = region_clearance_m(sc, regions, p);
    ASSERT_NEAR(got, want, 1e-12);
    // Points just inside the clearance resolve as p does.
    const int here = resolve_material(sc, regions, 0.5f, 0.5f, p);
    for (int k = 0; k < 8; ++k) {
      const double a = 6.283185307179586 * k / 8.0, r = 0.999 * got;
      EXPECT_EQ(resolve_material(sc, regions, 0.5f, 0.5f, p + glm::dvec3(r * std::cos(a), r * std::sin(a), 0.0)), here);
    }
  }
  // A texture mask gives no bound.
  json tex = mats;
  tex["t"]["regions"][0] = {{"mask", "assets/textures/tongue_lesion.png"}, {"threshold", 0.5}, {"material", "inside"}};
  json j = patch_scene(tex, "t", 1, 4);
  try {
    const Scene st = load_scene(JsonFile::from(j, std::string(OFL_SOURCE_DIR) + "/clearance_tex.json"));
    for (size_t m = 0; m < st.materials.size(); ++m)
      if (st.materials[m].dispatches()) EXPECT_EQ(region_clearance_m(st, int(m), glm::dvec3(0.0)), 0.0);
  } catch (const std::exception& e) {
    FAIL() << e.what();
  }
}

// The mask's side distance is the exact periodic Euclidean distance transform: against the brute
// force minimum over every texel of the other side and its wrapped copies, on a random texture.
TEST(LayeredVolume, MaskSideDistanceIsTheExactDistanceToTheOtherSide) {
  Texture t;
  t.width = 23;
  t.height = 17;
  Rng rng(3, 0);
  for (int i = 0; i < t.width * t.height; ++i) t.texels.push_back(float(rng.next_double() < 0.08 ? 0.9 : 0.1));
  const std::vector<float> d = side_distance_texels(t, 0.5);
  ASSERT_EQ(d.size(), t.texels.size());
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      const bool above = t.texels[size_t(y) * t.width + x] > 0.5f;
      double want = std::numeric_limits<double>::infinity();
      for (int yy = 0; yy < t.height; ++yy)
        for (int xx = 0; xx < t.width; ++xx) {
          if ((t.texels[size_t(yy) * t.width + xx] > 0.5f) == above) continue;
          for (int wy = -1; wy <= 1; ++wy)
            for (int wx = -1; wx <= 1; ++wx)
              want = std::min(want, std::hypot(double(xx + wx * t.width - x), double(yy + wy * t.height - y)));
        }
      ASSERT_NEAR(d[size_t(y) * t.width + x], want, 1e-5) << "texel " << x << ", " << y;
    }
  // One side only: nothing to reach.
  Texture flat = t;
  std::fill(flat.texels.begin(), flat.texels.end(), 0.2f);
  for (float v : side_distance_texels(flat, 0.5)) EXPECT_TRUE(std::isinf(v));
}

// A texture mask's clearance along the plane: within it resolve_material does not change (in every
// direction, the texture stretched twice as much along u as along v), and it is within two texels of
// the distance to the mask's contour (a disc of radius 20 texels, closed form) where the stretch is
// the same both ways; a surface whose texture coordinates do not change is never bounded.
TEST(LayeredVolume, MaskClearanceBoundsWhereTheRegionEnds) {
  Scene sc;
  Texture t;
  t.width = t.height = 128;
  constexpr double kR = 20.0;  // the contour: value 0.5 at kR texels from the centre, a linear ramp across it
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x)
      t.texels.push_back(float(std::clamp(0.5 + (kR - std::hypot(x + 0.5 - 64.0, y + 0.5 - 64.0)) / 4.0, 0.0, 1.0)));
  sc.textures.push_back(t);
  sc.materials.resize(3);
  sc.materials[0].name = "outside";
  sc.materials[1].name = "inside";
  Material& m = sc.materials[2];
  m.name = "regions";
  m.regions_base_name = "outside";
  m.regions_base = 0;
  MaterialRegion r;
  r.texture = 0;
  r.threshold = 0.5;
  r.material = 1;
  r.side_distance = side_distance_texels(t, 0.5);
  m.regions.push_back(r);
  // u = x / 10 mm, v = y / 20 mm on the plane z = 0.
  const glm::dvec3 gu(100.0, 0, 0), gv(0, 50.0, 0);
  const UvMetric aniso{glm::dot(gu, gu), 0.0, glm::dot(gv, gv)};
  Rng rng(17, 0);
  int bounded = 0;
  for (int i = 0; i < 400; ++i) {
    const glm::dvec3 p(0.01 * rng.next_double(), 0.02 * rng.next_double(), 0.0);
    const float u = float(p.x * 100.0), v = float(p.y * 50.0);
    const double c = region_clearance_m(sc, 2, p, u, v, aniso);
    ASSERT_GE(c, 0.0);
    bounded += c > 0;
    const int here = resolve_material(sc, 2, u, v, p);
    for (int k = 0; k < 16; ++k) {
      const double a = 6.283185307179586 * k / 16.0;
      const glm::dvec3 q = p + 0.999 * c * glm::dvec3(std::cos(a), std::sin(a), 0.0);
      ASSERT_EQ(resolve_material(sc, 2, float(q.x * 100.0), float(q.y * 50.0), q), here) << "point " << i << ", direction " << k;
    }
  }
  EXPECT_GT(bounded, 300);  // most of the plane lies more than 1.5 sqrt 2 texels from the contour
  // Isotropic stretch (u = x / 10 mm, v = y / 10 mm): 1 texel = 10 mm / 128; the bound against the
  // distance to the contour, r texels from the disc's centre.
  const UvMetric iso{1e4, 0.0, 1e4};
  const double texel_m = 0.01 / 128;
  for (int i = 0; i < 400; ++i) {
    const double ut = 128.0 * rng.next_double(), vt = 128.0 * rng.next_double();
    const double want = std::abs(std::hypot(ut - 64.0, vt - 64.0) - kR) * texel_m;
    const double c = region_clearance_m(sc, 2, glm::dvec3(0.0), float(ut / 128), float(vt / 128), iso);
    EXPECT_LE(c, want + 0.5 * texel_m) << ut << ", " << vt;
    EXPECT_GE(c, want - (1.5 * std::sqrt(2.0) + 0.75) * texel_m) << ut << ", " << vt;
  }
  // A threshold that float cannot hold (0.3): texels of 0.3f lie above it as resolve_material
  // compares, so a patch of them is a region, bounded like any other.
  Scene s3 = sc;
  std::fill(s3.textures[0].texels.begin(), s3.textures[0].texels.end(), 0.1f);
  for (int y = 60; y < 68; ++y)
    for (int x = 60; x < 68; ++x) s3.textures[0].texels[size_t(y) * 128 + x] = 0.3f;
  s3.materials[2].regions[0].threshold = 0.3;
  s3.materials[2].regions[0].side_distance = side_distance_texels(s3.textures[0], 0.3);
  ASSERT_EQ(resolve_material(s3, 2, 64.0f / 128, 64.0f / 128, glm::dvec3(0.0)), 1);
  for (int i = 0; i < 200; ++i) {
    const double ut = 40.0 + 48.0 * rng.next_double(), vt = 40.0 + 48.0 * rng.next_double();
    const float u = float(ut / 128), v = float(vt / 128);
    const double c = region_clearance_m(s3, 2, glm::dvec3(0.0), u, v, iso);
    ASSERT_TRUE(std::isfinite(c)) << ut << ", " << vt;
    const int here = resolve_material(s3, 2, u, v, glm::dvec3(0.0));
    for (int k = 0; k < 16; ++k) {
      const double a = 6.283185307179586 * k / 16.0;
      const float uq = float((ut + 0.999 * c / texel_m * std::cos(a)) / 128), vq = float((vt + 0.999 * c / texel_m * std::sin(a)) / 128);
      ASSERT_EQ(resolve_material(s3, 2, uq, vq, glm::dvec3(0.0)), here) << "point " << i << ", direction " << k;
    }
  }
  EXPECT_TRUE(std::isinf(region_clearance_m(sc, 2, glm::dvec3(0.0), 0.3f, 0.3f, UvMetric{})));
  EXPECT_TRUE(std::isinf(region_clearance_m(sc, 0, glm::dvec3(0.0), 0.3f, 0.3f, iso)));
}

TEST(LayeredVolume, SameImageAtAnyThreadCount) {
  const json j = patch_scene(discs({{"type", "layered_tissue"}, {"preset", "lateral_tongue"}},
                                   {{"type", "layered_tissue"}, {"preset", "blood_spot"}}),
                             "t", 1, 8);
  std::vector<float> first;
  for (int threads : {1, 2, 3}) {
    tbb::global_control g(tbb::global_control::max_allowed_parallelism, threads);
    const RenderResult r = render_quiet(j, "threads.json");
    if (first.empty()) first = r.image.data;
    else EXPECT_EQ(0, std::memcmp(first.data(), r.image.data.data(), 4 * first.size())) << threads << " threads";
  }
}

TEST(LayeredVolume, BadInputIsNamed) {
  const json tongue = {{"type", "layered_tissue"}, {"preset", "lateral_tongue"}};
  // A volume material beside a table one: refused, naming both and the field.
  json j = patch_scene(discs(tongue, tongue), "t", 1, 4);
  j["materials"]["inside"]["transport"] = "table";
  try {
    load_scene(JsonFile::from(j, "mixed.json"));
    ADD_FAILURE() << "mixed transports accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"outside\" uses the \"volume\" transport but \"inside\" does not"), std::string::npos)
        << e.what();
    EXPECT_NE(e.describe().find("/materials/t/regions/0/material"), std::string::npos) << e.describe();
  }
  // Columns that end differently (a white base at 1 mm beside semi-infinite tissue): refused.
  json k = patch_scene(discs(tongue, {{"type", "layered_tissue"},
                                      {"bottom", {{"type", "base"}, {"reflectance", 1.0}}},
                                      {"layers", {{{"name", "one"}, {"thickness_mm", 1.0}, {"ior", 1.4},
                                                   {"scattering", {{"g", 0.8}, {"mus_per_mm", 5.0}}}}}}}),
                       "t", 1, 4);
  try {
    load_scene(JsonFile::from(k, "columns.json"));
    ADD_FAILURE() << "columns of different ends accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("must end alike"), std::string::npos) << e.what();
  }
  // An unknown transport names the choices.
  json u = patch_scene({{"t", {{"type", "layered_tissue"}, {"preset", "lateral_tongue"}, {"transport", "volumes"}}}}, "t", 1, 4);
  try {
    load_scene(JsonFile::from(u, "unknown.json"));
    ADD_FAILURE() << "unknown transport accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"volume\""), std::string::npos) << e.what();
  }
}
