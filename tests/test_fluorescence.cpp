// Fluorescence: EEM input checks, the Stokes mask, the energy check of materials, the excitation
// sampler (chi-square), the fluorophore library, and the closed-form cases of docs/transport.md.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "materials/material_parser.h"
#include "renderer/validation/cases/closed_form_cases.h"
#include "renderer/core/errors/error.h"
#include "renderer/render/integrator/render_tables.h"
#include "renderer/render/material/albedo_matrix.h"
#include "renderer/scene/scene.h"
#include "renderer/spectral/chromophores/fluorophore_library.h"
#include "tests/cli_runner.h"
#include "tests/stat_utils.h"

using namespace ofl;

namespace {
std::string write_tmp(const std::string& name, const std::string& text) {
  auto p = std::filesystem::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p.string();
}
}  // namespace

TEST(Eem, ResampleKeepsZeroOnAndBelowDiagonal) {
  // A file with (unphysical) entries everywhere, including below the diagonal.
  std::string text = "emission_nm\\excitation_nm,400,420,440,460\n";
  for (int em = 380; em <= 560; em += 10) {
    text += std::to_string(em);
    for (int k = 0; k < 4; ++k) text += ",1";
    text += "\n";
  }
  Eem e = read_eem_csv(write_tmp("ofl_full.csv", text));
  WavelengthGrid g{380, 560, 5};
  GridEem r = resample(e, g);
  int nonzero = 0;
  for (int em = 0; em < g.size(); ++em)
    for (int ex = 0; ex < g.size(); ++ex) {
      if (em <= ex) EXPECT_EQ(r.at(em, ex), 0.0) << em << "," << ex;
      else nonzero += r.at(em, ex) > 0;
    }
  EXPECT_GT(nonzero, 100);
  // Above the diagonal and inside the file's range the bin means of a constant are 1.
  EXPECT_NEAR(r.at(g.index_of(500), g.index_of(420)), 1.0, 1e-12);
}

TEST(Eem, BadEntriesAreInputErrorsWithLine) {
  auto nan = write_tmp("ofl_nan_eem.csv", "emission_nm\\excitation_nm,400,410\n450,1,2\n460,NaN,1\n");
  try {
    read_eem_csv(nan);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), nan);
    EXPECT_EQ(e.field(), "line 3 column 2");
  }
  auto neg = write_tmp("ofl_neg_eem.csv", "emission_nm\\excitation_nm,400,410\n450,1,2\n460,1,-0.5\n");
  EXPECT_THROW(read_eem_csv(neg), InputError);
}

TEST(Eem, MaterialThatCreatesEnergyIsRejected) {
  auto scene = [](double r, double c) {
    nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                        {"camera", {{"position", {0, 0, 1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 20}, {"resolution", {4, 4}}}},
                        {"materials", {{"t", {{"type", "fluorescent"}, {"reflectance", r}, {"fluorophores", {{{"name", "FAD"}, {"concentration", c}}}}}}}},
                        {"geometry", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 0.1}, {"material", "t"}}}}};
    return JsonFile::from(j, "energy.json");
  };
  EXPECT_NO_THROW(load_scene(scene(0.5, 0.49)));
  try {
    load_scene(scene(0.5, 0.6));  // FAD's photon albedo peaks at 1 (normalised): 0.5 + 0.6 > 1
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/materials/t");
    EXPECT_NE(std::string(e.what()).find("creates energy"), std::string::npos) << e.what();
  }
}

TEST(Eem, MoreFluorophoresThanTheRendererHoldsIsAnInputError) {
  // The renderer keeps a surface point's concentrations in a fixed array; one layer more than it
  // holds must be refused at load (naming the list), never silently dropped at render time.
  auto scene = [](int layers) {
    nlohmann::json list = nlohmann::json::array();
    for (int i = 0; i < layers; ++i) list.push_back({{"name", "FAD"}, {"concentration", 0.001}});
    nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                        {"camera", {{"position", {0, 0, 1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 20}, {"resolution", {4, 4}}}},
                        {"materials", {{"t", {{"type", "fluorescent"}, {"reflectance", 0.5}, {"fluorophores", list}}}}},
                        {"geometry", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 0.1}, {"material", "t"}}}}};
    return JsonFile::from(j, "many.json");
  };
  EXPECT_NO_THROW(load_scene(scene(kMaxFluorophoresPerMaterial)));
  try {
    load_scene(scene(kMaxFluorophoresPerMaterial + 1));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/materials/t/fluorophores");
    EXPECT_NE(std::string(e.what()).find("at most"), std::string::npos) << e.what();
  }
}

TEST(Eem, PairNormalisationAndStokes) {
  WavelengthGrid g{350, 800, 5};
  GridEem t = load_fluorophore("teeth", g);
  auto a = t.photon_albedo();
  EXPECT_NEAR(*std::max_element(a.begin(), a.end()), 1.0, 1e-9);
  for (int em = 0; em < g.size(); ++em)
    for (int ex = em; ex < g.size(); ++ex) EXPECT_EQ(t.at(em, ex), 0.0);
}

TEST(FluorophoreLibrary, HasTheOralFluorophoresWithLiteraturePeaks) {
  // Emission peaks from the literature (DaCosta et al. 2003; Wagnieres et al. 1998):
  // NADH ~460, FAD ~525, protoporphyrin ~630, chlorophyll-a ~675, teeth ~480 nm, and the porphyrin forms.
  WavelengthGrid g{350, 830, 5};
  std::map<std::string, std::pair<double, double>> expect = {
      {"NADH", {440, 480}}, {"FAD", {510, 545}}, {"protoporphyrin", {620, 645}}, {"chlorophyll_a", {660, 690}}, {"teeth", {460, 500}},
      {"collagen", {380, 460}}, {"elastin", {410, 480}}, {"keratin", {400, 500}},
      // Porphyrin forms (main band; Bjurshammar 2017: 636 nm; Sudhakar 1994: 628; Uttamlal 2008: 656; Wagnieres 1998: 626).
      {"porphyrin_bacterial", {626, 646}}, {"porphyrin_sudhakar", {618, 638}}, {"porphyrin_uttamlal", {646, 666}},
      {"porphyrin_wagnieres", {616, 636}}};
  auto lib = fluorophore_library();
  EXPECT_EQ(lib.size(), expect.size());
  for (auto& e : lib) {
    ASSERT_TRUE(expect.count(e.name)) << e.name;
    GridEem m = load_fluorophore(e.name, g);
    // Emission peak under 405 nm excitation (the instrument's light).
    int ex = g.index_of(405), best = 0;
    for (int em = 0; em < g.size(); ++em) if (m.at(em, ex) > m.at(best, ex)) best = em;
    double peak = g.wavelength(best);
    EXPECT_GE(peak, expect[e.name].first) << e.name;
    EXPECT_LE(peak, expect[e.name].second) << e.name;
  }
  auto r = test::run_cli("fluorophores --json");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.output.find("\"protoporphyrin\""), std::string::npos);
}

TEST(ExcitationSampler, MatchesTheMixtureRow) {
  // Material with FAD and NADH; sample the excitation wavelength for em = 530 nm and compare with
  // c_FAD Phi_FAD(530, .) + c_NADH Phi_NADH(530, .) normalised.
  nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                      {"camera", {{"position", {0, 0, 1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 20}, {"resolution", {4, 4}}}},
                      {"materials", {{"t", {{"type", "fluorescent"}, {"reflectance", 0.2},
                                            {"fluorophores", {{{"name", "FAD"}, {"concentration", 0.2}}, {{"name", "NADH"}, {"concentration", 0.3}}}}}}}},
                      {"geometry", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 0.1}, {"material", "t"}}}}};
  Scene sc = load_scene(JsonFile::from(j, "sampler.json"));
  RenderTables t(sc);
  LocalMaterial lm{&t.materials[0]};
  lm.nf = 2;
  lm.conc[0] = 0.2f;
  lm.conc[1] = 0.3f;
  int n = t.n, em = sc.grid().index_of(530);
  std::vector<double> expected(n, 0.0), observed(n, 0.0);
  double total = 0;
  for (int ex = 0; ex < n; ++ex) {
    expected[ex] = 0.2 * sc.eems[0].at(em, ex) + 0.3 * sc.eems[1].at(em, ex);
    total += expected[ex];
  }
  Rng rng(5, 9);
  const int N = 200000;
  float F = fluor_total(lm, em);
  for (int i = 0; i < N; ++i) observed[sample_excitation(lm, em, F, rng.next_float(), n)] += 1;
  for (int ex = em; ex < n; ++ex) EXPECT_EQ(observed[ex], 0) << "sampled at or above the emission wavelength";
  for (auto& e : expected) e *= N / total;
  auto r = test::chi_square(observed, expected);
  EXPECT_GT(r.p_value, 1e-4) << "chi2 " << r.statistic << " dof " << r.dof;
  // Power: the FAD row alone is a different density and must be rejected.
  std::vector<double> fad_only(n, 0.0);
  double ft = 0;
  for (int ex = 0; ex < n; ++ex) ft += fad_only[ex] = sc.eems[0].at(em, ex);
  for (auto& e : fad_only) e *= N / ft;
  EXPECT_LT(test::chi_square(observed, fad_only).p_value, 1e-6);
}

// Closed forms with fluorescence.
TEST(FluorescentClosedForm, PatchUnderBroadbandAndNarrow385Led) {
  for (const char* c : {"fluorescent_patch", "fluorescent_patch_385"}) {
    BenchResult r = run_bench_case(c, 256, 1);
    EXPECT_LT(r.mean_rel_error, 0.01) << r.to_json().dump();
    EXPECT_GT(r.extra["fluorescence_share_of_radiance"].get<double>(), 0.05) << c;  // the case really tests fluorescence
    // The separate fluorescence layer matches the fluorescent part of the closed form.
    EXPECT_LT(r.extra["fluorescence_layer_max_band_error"].get<double>(), 0.02) << c;
  }
}

TEST(FluorescentClosedForm, DiskLedSharesPathsBetweenStrategiesWithoutBias) {
  // Deterministic direct excitation gives next-event estimation all fluorescent direct light and
  // BSDF hits of the LED after a re-radiation nothing; sampled excitation uses MIS for both. Both
  // must converge to the closed form.
  BenchResult d = run_bench_case("fluorescent_disk_led", 256, 1);
  EXPECT_LT(d.mean_rel_error, 0.01) << d.to_json().dump();
  BenchResult s = run_bench_case("fluorescent_patch", BenchOptions{256, 2, true, ""});
  EXPECT_LT(s.mean_rel_error, 0.01) << s.to_json().dump();
  BenchResult sd = run_bench_case("fluorescent_disk_led", BenchOptions{512, 3, true, ""});
  EXPECT_LT(sd.mean_rel_error, 0.04) << sd.to_json().dump();  // unbiased but noisy: regions of ~1000 px
}

TEST(FluorescentClosedForm, CameraImportanceSamplingStaysUnbiased) {
  // Camera wavelengths drawn half by the OralEye camera's system QE (its 475 nm long-pass blocks
  // the blue bands): every band, blocked or not, still converges to the closed form.
  BenchOptions o{256, 4, false, std::string(OFL_SOURCE_DIR) + "/scenes/cameras/oraleye.json"};
  BenchResult r = run_bench_case("fluorescent_patch", o);
  EXPECT_LT(r.mean_rel_error, 0.01) << r.to_json().dump();
  EXPECT_LT(r.max_rel_error, 0.04) << r.to_json().dump();
}

TEST(FluorescentClosedForm, SphereAlbedoMatrixEveryBandWithinOnePercent) {
  BenchResult r = run_bench_case("fluorescent_sphere", 1024, 1);
  const BenchRegion* whole = nullptr;
  for (auto& g : r.regions) if (g.name == "whole") whole = &g;
  ASSERT_NE(whole, nullptr);
  EXPECT_LT(whole->max_band_error, 0.01) << r.to_json().dump();
  // Without fluorescence excited by fluorescence some band would be more than 5 % off, so passing
  // proves the cascade.
  EXPECT_GT(r.extra["cascade_effect_max_band"].get<double>(), 0.05);
  EXPECT_LE(r.extra["max_photon_albedo"].get<double>(), 1.0);
}

TEST(FluorescentClosedForm, ReradiationOnlyHasNothingAtOrBelowExcitation) {
  BenchResult r = run_bench_case("reradiation_only", 1024, 1);
  EXPECT_EQ(r.extra["max_radiance_at_or_below_excitation"].get<double>(), 0.0);
  EXPECT_GT(r.extra["max_radiance_above_excitation"].get<double>(), 0.0);
  EXPECT_LT(r.mean_rel_error, 0.01) << r.to_json().dump();
}
