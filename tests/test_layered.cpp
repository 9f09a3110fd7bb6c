// Layered tissue (materials/description/layered.h): the walk's sampling routines against their densities, the
// interfaces against Fresnel and Snell, the BSDF against closed forms (fluorescent slab, furnace,
// Lambertian under a film, the thin-layer limit), every MCML slab, and input errors.
#include <gtest/gtest.h>

#include <cstdlib>

#include <cmath>

#include <glm/geometric.hpp>

#include <tbb/global_control.h>

#include <fstream>

#include "renderer/validation/harness/bench_check.h"
#include "renderer/validation/cases/closed_form_cases.h"
#include "renderer/validation/references/mcml.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/render/render_job.h"
#include "renderer/render/stack/stack_walk.h"
#include "stat_utils.h"

using namespace ofl;

TEST(LayeredSampling, HenyeyGreensteinMatchesItsDensity) {
  for (double g : {0.0, 0.5, 0.9, -0.3}) {
    const int bins = 40, n = 200000;
    std::vector<double> obs(bins, 0.0), exp(bins, 0.0);
    Rng rng(7, 1);
    glm::dvec3 d = glm::normalize(glm::dvec3(0.3, -0.2, 0.9));
    for (int i = 0; i < n; ++i) {
      glm::dvec3 w = sample_hg(g, d, rng.next_double(), rng.next_double());
      double c = std::clamp(glm::dot(w, d), -1.0, 1.0);
      obs[std::min(bins - 1, int((c + 1) / 2 * bins))] += 1;
    }
    for (int b = 0; b < bins; ++b) {  // integral of 2 pi p(c) dc over the bin, midpoint-refined
      double lo = -1 + 2.0 * b / bins, hi = lo + 2.0 / bins, s = 0;
      for (int k = 0; k < 200; ++k) s += 2 * kPi * hg_phase(g, lo + (k + 0.5) * (hi - lo) / 200) * (hi - lo) / 200;
      exp[b] = s * n;
    }
    auto cs = test::chi_square(obs, exp);
    EXPECT_GT(cs.p_value, 1e-4) << "g = " << g << " chi2 " << cs.statistic << " dof " << cs.dof;
  }
}

TEST(LayeredInterface, SmoothInterfaceReflectsWithFresnelAndRefractsWithSnell) {
  DielectricInterface smooth(0.0, 1.0, 1.4);  // air above, n = 1.4 below
  for (double theta : {0.0, 30.0, 60.0, 80.0}) {
    double t = theta * kPi / 180;
    glm::dvec3 d(std::sin(t), 0, -std::cos(t));  // going down into the denser medium
    Rng rng(3, uint64_t(theta));
    const int n = 100000;
    int reflected = 0;
    for (int i = 0; i < n; ++i) {
      InterfaceEvent e = smooth.scatter(d, rng);
      ASSERT_DOUBLE_EQ(e.weight, 1.0);
      if (!e.transmitted) {
        ++reflected;
        EXPECT_NEAR(e.dir.z, std::cos(t), 1e-12);
      } else {
        EXPECT_NEAR(std::sin(t), 1.4 * std::hypot(e.dir.x, e.dir.y), 1e-12);  // Snell
        EXPECT_LT(e.dir.z, 0);
      }
    }
    double F = fresnel_dielectric(std::cos(t), 1.4);
    EXPECT_NEAR(double(reflected) / n, F, 4 * std::sqrt(F * (1 - F) / n) + 1e-9) << theta;
  }
  // From inside beyond the critical angle (45.6 deg): always reflected.
  glm::dvec3 up(std::sin(1.0), 0, std::cos(1.0));
  Rng rng(1, 1);
  for (int i = 0; i < 100; ++i) EXPECT_FALSE(smooth.scatter(up, rng).transmitted);
}

TEST(LayeredInterface, RoughInterfaceIsLosslessAndKeepsSides) {
  DielectricInterface rough(0.25, 1.0, 1.33);
  EXPECT_NEAR(rough.valid_fraction(glm::dvec3(0, 0, -1)), 1.0, 0.01);  // at normal incidence nearly every sample is valid
  for (double theta : {0.0, 45.0, 80.0})
    for (bool from_below : {false, true}) {
      double t = theta * kPi / 180;
      glm::dvec3 d(std::sin(t), 0, from_below ? std::cos(t) : -std::cos(t));
      Rng rng(5, uint64_t(theta * 10 + from_below));
      int reflected = 0;
      const int n = 20000;
      for (int i = 0; i < n; ++i) {
        InterfaceEvent e = rough.scatter(d, rng);
        ASSERT_DOUBLE_EQ(e.weight, 1.0) << theta;
        // Reflection stays on the incident side, refraction crosses.
        bool same_side = (e.dir.z > 0) == (d.z < 0);
        EXPECT_EQ(same_side, !e.transmitted);
        reflected += !e.transmitted;
      }
      double V = rough.valid_fraction(d);
      EXPECT_GT(V, 0.5);
      EXPECT_LE(V, 1.0);
      if (!from_below && theta == 0.0) {
        EXPECT_NEAR(double(reflected) / n, fresnel_dielectric(1.0, 1.33), 0.01);
      }
      // From inside the film beyond the critical angle (48.8 deg) almost everything reflects.
      if (from_below && theta == 80.0) {
        EXPECT_GT(double(reflected) / n, 0.9);
      }
    }
}

// V(d), the probability that one rough sample from travel direction d is valid, which the
// reflection BRDF and the next-event connection divide by: against a Monte Carlo count of valid
// single tries (the Fresnel branch drawn by its probability), from both sides, near grazing too
// (where reflections into the wrong side are common and the branch's weight matters most).
TEST(LayeredInterface, RoughValidFractionIsTheProbabilityOfAValidTry) {
  DielectricInterface rough(0.4, 1.0, 1.33);
  for (double theta : {0.0, 40.0, 70.0, 80.0, 86.0})
    for (bool from_below : {false, true}) {
      double t = theta * kPi / 180;
      glm::dvec3 d(std::sin(t), 0, from_below ? std::cos(t) : -std::cos(t));
      Rng rng(7, uint64_t(theta * 10 + from_below));
      // scatter() retries invalid tries: the tries it needs are geometric with mean 1 / V.
      const int n = 100000;
      long long tries = 0;
      for (int i = 0; i < n; ++i) {
        glm::dvec3 dd = d;
        struct Counting {
          Rng& r;
          long long& calls;
          double next_double() { ++calls; return r.next_double(); }
        } counting{rng, tries};
        rough.scatter(dd, counting);
      }
      const double V_mc = double(n) / (double(tries) / 3.0);  // three random numbers per try
      const double se = V_mc * std::sqrt((1.0 - V_mc) / n);
      EXPECT_NEAR(rough.valid_fraction(d), V_mc, 4 * se + 0.003)
          << "theta " << theta << (from_below ? " from below" : " from above");
    }
}

class LayeredCheck : public ::testing::TestWithParam<const char*> {};

TEST_P(LayeredCheck, AgreesWithClosedForm) {
  CheckCaseResult r = run_check_case(GetParam(), 0, 11);
  for (const auto& c : r.checks) EXPECT_TRUE(c.pass()) << c.quantity << ": " << c.value << " vs " << c.reference << " +- " << c.tolerance;
  EXPECT_FALSE(r.checks.empty());
}

INSTANTIATE_TEST_SUITE_P(Cases, LayeredCheck,
                         ::testing::Values("layered_fluorescent_escape", "layered_scattering_fluorescence", "layered_furnace",
                                           "layered_coated_lambertian"));

TEST(LayeredRender, ThinLayerLimitIsTheSurfaceMaterial) {
  BenchResult r = run_bench_case("layered_thin_limit", 256, 1);
  EXPECT_LT(r.mean_rel_error, 0.01) << r.to_json().dump();
  EXPECT_LT(r.max_rel_error, 0.03) << r.to_json().dump();
}

TEST(LayeredRender, FluorescentSlabMatchesPerPixelClosedForm) {
  BenchResult r = run_bench_case("layered_fluorescent_slab", 256, 1);
  EXPECT_LT(r.mean_rel_error, 0.01) << r.to_json().dump();
  EXPECT_LT(r.max_rel_error, 0.03) << r.to_json().dump();
}

// The same slab through the tabulated response (transport "table"): the fluorescence factorised
// through depth, interpolated between the table's cosine nodes. The table's own noise and its
// projection on the cosine tents add to the render's noise: measured 1.2 % mean, 3.8 % worst band
// of a region (the walk: under 1 % and 3 %).
TEST(LayeredRender, FluorescentSlabTableMatchesPerPixelClosedForm) {
  BenchResult r = run_bench_case("layered_fluorescent_slab_table", 256, 1);
  EXPECT_LT(r.mean_rel_error, 0.015) << r.to_json().dump();
  EXPECT_LT(r.max_rel_error, 0.05) << r.to_json().dump();
}

class LayeredMcml : public ::testing::TestWithParam<std::string> {};

TEST_P(LayeredMcml, SlabAgreesWithMcml) {
  auto dir = mcml_case_dir();
  auto runs = read_mci(dir / (GetParam() + ".mci"));
  McmlOutput ref = read_mco(dir / (GetParam() + ".mco"));
  // 2e5 photons against MCML's 1e6: the tolerance combines both runs' standard errors.
  CheckCaseResult r = mcml_case(runs.at(0), &ref, 200000, 17);
  ASSERT_FALSE(r.checks.empty());
  for (const auto& c : r.checks) EXPECT_TRUE(c.pass()) << c.quantity << ": " << c.value << " vs MCML " << c.reference << " +- " << c.tolerance;
}

INSTANTIATE_TEST_SUITE_P(Slabs, LayeredMcml, ::testing::ValuesIn(mcml_case_names()),
                         [](const auto& info) {
                           std::string s = info.param;
                           for (char& c : s)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return s;
                         });

TEST(LayeredMcml, ReadsFilesAndNamesBadLines) {
  auto dir = mcml_case_dir();
  auto runs = read_mci(dir / "mucosa_405.mci");
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].layers.size(), 2u);
  EXPECT_DOUBLE_EQ(runs[0].layers[1].mus_per_cm, 267);
  McmlOutput o = read_mco(dir / "mucosa_405.mco");
  EXPECT_NEAR(o.rd, 0.0673991, 1e-9);
  EXPECT_EQ(o.a_layer.size(), 2u);
  auto bad = std::filesystem::temp_directory_path() / "ofl_bad.mci";
  std::ofstream(bad) << "1.0\n1\nx.mco A\n1000\n0.01 0.01\n10 10 10\n1\n1\n1.37 0.1 abc 0.9 0.1\n1\n";
  try {
    read_mci(bad);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "line 9");
    EXPECT_NE(std::string(e.what()).find("layer mus"), std::string::npos);
  }
}

namespace {
Scene layered_scene(const nlohmann::json& material) {
  nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                      {"integrator", {{"spp", 8}, {"wavelengths", {{"min_nm", 380}, {"max_nm", 720}, {"step_nm", 5}}}}},
                      {"camera", {{"position", {0, 0, 0.1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 20}, {"resolution", {12, 10}}}},
                      {"materials", {{"t", material}}},
                      {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.1, 0, 0}}, {"v", {0, 0.1, 0}}, {"material", "t"}}}},
                      {"lights", {{{"spd", {{"type", "gaussian"}, {"peak_nm", 405}, {"fwhm_nm", 15}}}, {"radiant_intensity_W_sr", 1.0},
                                   {"position", {0.05, 0, 0.07}}, {"target", {0, 0, 0}}, {"radius_m", 0.002}}}}};
  return load_scene(JsonFile::from(j, "layered.json"));
}

std::string field_of(const nlohmann::json& material) {
  try {
    layered_scene(material);
  } catch (const InputError& e) {
    return e.field() + " | " + e.what();
  }
  return "no error";
}
}  // namespace

TEST(LayeredParse, ErrorsNameTheField) {
  nlohmann::json ok = {{"type", "layered_tissue"},
                       {"layers", {{{"name", "epi"}, {"thickness_mm", 0.3}, {"scattering", {{"g", 0.9}, {"mus_prime_per_mm", {{"a", 2}, {"b", 1.2}}}}},
                                    {"fluorophores", {{{"name", "FAD"}, {"mua_per_mm", 0.1}, {"quantum_yield", 0.3}}}}},
                                   {{"name", "stroma"}, {"absorption", {{"blood", {{"volume_fraction", 0.02}}}}},
                                    {"scattering", {{"g", 0.9}, {"mus_prime_per_mm", {{"a", 2}, {"b", 1.2}}}}}}}}};
  EXPECT_EQ(field_of(ok), "no error");
  auto with = [&](const std::string& ptr, const nlohmann::json& v) {
    nlohmann::json m = ok;
    m[nlohmann::json::json_pointer(ptr)] = v;
    return field_of(m);
  };
  EXPECT_NE(with("/layers/0/fluorophores/0/quantum_yield", 1.5).find("/materials/t/layers/0/fluorophores/0/quantum_yield"), std::string::npos);
  EXPECT_NE(with("/layers/0/scattering/g", 1.0).find("/materials/t/layers/0/scattering/g"), std::string::npos);
  EXPECT_NE(with("/layers/0/thikness_mm", 1.0).find("thikness_mm"), std::string::npos);
  EXPECT_NE(with("/layers/1/thickness_mm", 2.0).find("/materials/t/layers/1"), std::string::npos);  // finite last layer, no bottom
  // A coefficient table that stops short of the transport grid is refused, not extended as zero.
  std::string short_table = with("/layers/0/absorption", {{"mua_per_mm", {{"type", "points"}, {"points", {{400, 0.1}, {700, 0.1}}}}}});
  EXPECT_NE(short_table.find("covers 400-700 nm"), std::string::npos) << short_table;
  EXPECT_NE(with("/preset", "spleen").find("no layered tissue preset"), std::string::npos);
  EXPECT_NE(with("/transport", "fast").find("/materials/t/transport"), std::string::npos);
  EXPECT_NE(with("/table_photons", 5).find("/materials/t/table_photons"), std::string::npos);
}

TEST(LayeredRender, BitIdenticalWithOneAndTwoThreads) {
  nlohmann::json m = {{"type", "layered_tissue"},
                      {"coating", {{"ior", 1.33}, {"roughness", 0.25}}},
                      {"layers", {{{"name", "epi"}, {"thickness_mm", 0.3}, {"scattering", {{"g", 0.9}, {"mus_prime_per_mm", {{"a", 2}, {"b", 1.2}}}}},
                                   {"fluorophores", {{{"name", "FAD"}, {"mua_per_mm", 0.1}, {"quantum_yield", 0.3}}}}},
                                  {{"name", "stroma"}, {"absorption", {{"blood", {{"volume_fraction", 0.02}}}}},
                                   {"scattering", {{"g", 0.9}, {"mus_prime_per_mm", {{"a", 2}, {"b", 1.2}}}}},
                                   {"fluorophores", {{{"name", "collagen"}, {"mua_per_mm", 0.2}, {"quantum_yield", 0.1}}}}}}}};
  // Both transports: the table is filled by walks seeded per (node, wavelength group), not per thread.
  // The on-disk cache is off here, so that each render fills its table with its own thread count.
  const char* cache = std::getenv("OFL_CACHE_DIR");
  const std::string saved = cache ? cache : "";
  ::setenv("OFL_CACHE_DIR", "off", 1);
  for (const char* transport : {"walk", "table"}) {
    m["transport"] = transport;
    m["table_photons"] = 500;
    Scene sc = layered_scene(m);
    RenderOptions opt;
    opt.progress = false;
    opt.aovs = false;
    auto run = [&](int threads) {
      tbb::global_control c(tbb::global_control::max_allowed_parallelism, threads);
      return render(sc, opt).image.data;
    };
    auto a = run(1), b = run(2);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_TRUE(a == b) << transport;
    double sum = 0;
    for (float v : a) sum += v;
    EXPECT_GT(sum, 0) << transport;
  }
  if (cache) ::setenv("OFL_CACHE_DIR", saved.c_str(), 1);
  else ::unsetenv("OFL_CACHE_DIR");
}
