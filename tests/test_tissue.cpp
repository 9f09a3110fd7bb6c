// Oral tissue presets are calibrated against measurements: the fluorescence they return above
// 480 nm under a 405 nm LED (teeth: 395 nm), as a fraction of what a white Lambertian target
// returns, lies in the range measured on volunteers (oe_tongue_lip; SCIEN teeth data).
#include <gtest/gtest.h>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/render/render_job.h"
#include "renderer/spectral/chromophores/hemoglobin.h"
#include "renderer/spectral/spectra/units.h"
#include "tests/tissue_ratio.h"

#include <filesystem>
#include <fstream>

using namespace ofl;

using ofl::test::fluorescence_ratio;

TEST(TissuePresets, FluorescenceRatioMatchesMeasurements) {
  // Measured (see assets/tissues/*.json "calibration"): tongue 3.3e-4..6.0e-4, lip 2.2e-4..2.7e-4,
  // teeth 5.4e-3..9.7e-3 (395 nm flashlight).
  double tongue = fluorescence_ratio({{"type", "tissue"}, {"preset", "tongue"}}, 405);
  double lip = fluorescence_ratio({{"type", "tissue"}, {"preset", "lip"}}, 405);
  double teeth = fluorescence_ratio({{"type", "teeth"}}, 395);
  EXPECT_GT(tongue, 3.3e-4);
  EXPECT_LT(tongue, 6.0e-4);
  EXPECT_GT(lip, 2.0e-4);
  EXPECT_LT(lip, 3.0e-4);
  EXPECT_GT(teeth, 5.4e-3);
  EXPECT_LT(teeth, 9.7e-3);
  std::printf("fluorescence / white target: tongue %.3g, lip %.3g, teeth %.3g\n", tongue, lip, teeth);
}

TEST(TissuePresets, OverridesAndErrors) {
  auto mk = [](nlohmann::json m) {
    nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                        {"camera", {{"position", {0, 0, 1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 20}, {"resolution", {4, 4}}}},
                        {"materials", {{"t", m}}},
                        {"geometry", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 0.1}, {"material", "t"}}}}};
    return load_scene(JsonFile::from(j, "overrides.json"));
  };
  Scene s = mk({{"type", "tissue"}, {"preset", "tongue"}, {"concentrations", {{"protoporphyrin", 1e-3}, {"chlorophyll_a", 2e-4}}},
                {"coating", false}});
  const Material& m = s.materials[0];
  EXPECT_FALSE(m.coating.enabled);
  double pp = -1, chl = -1;
  for (auto& f : m.fluorophores) {
    if (f.name == "protoporphyrin") pp = f.concentration;
    if (f.name == "chlorophyll_a") chl = f.concentration;
  }
  EXPECT_DOUBLE_EQ(pp, 1e-3);
  EXPECT_DOUBLE_EQ(chl, 2e-4);
  try {
    mk({{"type", "tissue"}, {"preset", "spleen"}});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/materials/t/preset");
  }
  EXPECT_THROW(mk({{"type", "tissue"}, {"preset", "tongue"}, {"fluorescence_scale", 5000.0}}), InputError);  // creates energy
}

namespace {
Scene patch_scene(const nlohmann::json& material, const std::string& name) {
  nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                      {"integrator", {{"spp", 32}, {"max_depth", 1}, {"wavelengths", {{"min_nm", 400}, {"max_nm", 700}, {"step_nm", 5}}},
                                      {"output_bands", {{"min_nm", 405}, {"max_nm", 695}, {"step_nm", 5}}}}},
                      {"camera", {{"position", {0, 0, 0.1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 2}, {"resolution", {8, 8}}}},
                      {"materials", {{"m", material}}},
                      {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.1, 0, 0}}, {"v", {0, 0.1, 0}}, {"material", "m"}}}},
                      {"lights", {{{"spd", 1.0}, {"radiant_intensity_W_sr", 1.0}, {"position", {0.07, 0, 0.07}}, {"target", {0, 0, 0}}}}}};
  return load_scene(JsonFile::from(j, name));
}
double band_mean(const SpectralImage& img, int b) {
  double s = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) s += img.pixel(x, y)[b];
  return s / (img.width * img.height);
}
}  // namespace

TEST(TissueBlood, LayerDimsReflectanceByTransmittanceInAndOut) {
  // Bare (uncoated, non-fluorescent) tongue with and without a blood layer: per 5 nm band the
  // radiance ratio is T_out T_in = 10^-(1 + f) OD, with the hemoglobin Q-band dips at 542 / 577 nm.
  nlohmann::json bare = {{"type", "tissue"}, {"preset", "tongue"}, {"coating", false}, {"fluorescence_scale", 0.0}};
  nlohmann::json blood = bare;
  blood["blood"] = {{"thickness_um", 20}, {"saturation", 0.8}, {"excitation_path_factor", 1.0}};
  Scene a = patch_scene(bare, "bare.json"), b = patch_scene(blood, "blood.json");
  RenderResult ra = render(a), rb = render(b);
  BloodAbsorber ab = BloodAbsorber::whole_blood(20, 0.8);
  for (double nm : {420.0, 500.0, 540.0, 560.0, 575.0, 650.0}) {
    int band = int((nm - 405) / 5), bin = b.grid().index_of(nm);
    double expect = b.materials[0].layer_out[bin] * b.materials[0].layer_in[bin];
    EXPECT_NEAR(band_mean(rb.image, band) / band_mean(ra.image, band), expect, 0.01 * expect + 1e-4) << nm;
    // The layer is Prahl's hemoglobin: 10^-2 OD at the bin centre, within the bin-mean spread.
    EXPECT_NEAR(expect, std::pow(10.0, -2 * blood_optical_density(ab, nm)), 0.1 * expect + 1e-3) << nm;
  }
  // The oxy-hemoglobin Q bands: 542 and 577 nm are darker than 560 nm between them.
  auto ratio = [&](double nm) { int k = int((nm - 405) / 5); return band_mean(rb.image, k) / band_mean(ra.image, k); };
  EXPECT_LT(ratio(540), ratio(560));
  EXPECT_LT(ratio(575), ratio(560));
}

TEST(TissueBlood, DiagnosisReportBecomesMaterialOptions) {
  auto report = std::filesystem::temp_directory_path() / "ofl_diag_report.json";
  std::ofstream(report) << nlohmann::json{
      {"causes",
       {{{"name", "blood_absorption"}, {"parameters", {{"oxy_uM_cm", 3.8}, {"deoxy_uM_cm", 2.3}}}, {"uncertainty", {{"oxy_uM_cm", 0.4}, {"deoxy_uM_cm", 0.7}}}},
        {{"name", "extra_fluorophore"}, {"parameters", {{"fluorophore", "chlorophyll_a"}, {"mean_fraction", 0.05}}}, {"uncertainty", {{"mean_fraction", 0.01}}}},
        {{"name", "emission_broadening"}, {"parameters", {{"fwhm_nm", 50.0}}}, {"uncertainty", {{"fwhm_nm", 4.0}}}}}},
      {"model_options", {{"blood_excitation_path_factor", 0.0}}}}.dump();
  Scene plain = patch_scene({{"type", "tissue"}, {"preset", "tongue"}}, "plain.json");
  Scene diag = patch_scene({{"type", "tissue"}, {"preset", "tongue"}, {"diagnosis", report.string()}}, "diag.json");
  const Material& m = diag.materials[0];
  ASSERT_FALSE(m.layer_out.empty());
  // excitation_path_factor 0: only the emission is attenuated.
  for (double t : m.layer_in) EXPECT_DOUBLE_EQ(t, 1.0);
  EXPECT_LT(m.layer_out[diag.grid().index_of(577)], m.layer_out[diag.grid().index_of(600)]);
  // Chlorophyll-a joins with a concentration giving it 5 % of the fluorescence under 405 nm.
  double chl = -1;
  for (auto& f : m.fluorophores) if (f.name == "chlorophyll_a") chl = f.concentration;
  EXPECT_GT(chl, 0);
  // Emission broadening: FAD's emission under 450 nm excitation is wider than the library's.
  auto width = [&](const Scene& s, const std::string& name) {
    for (auto& f : s.materials[0].fluorophores)
      if (f.name == name) {
        const GridEem& e = s.eems[f.eem];
        int ex = s.grid().index_of(450);
        double m0 = 0, m1 = 0, m2 = 0;
        for (int em = 0; em < e.n(); ++em) {
          double v = e.at(em, ex), l = s.grid().wavelength(em);
          m0 += v; m1 += v * l; m2 += v * l * l;
        }
        return std::sqrt(m2 / m0 - (m1 / m0) * (m1 / m0));
      }
    return 0.0;
  };
  double w0 = width(plain, "FAD"), w1 = width(diag, "FAD");
  // Gaussian blur of FWHM 50 nm adds sigma^2 = (50 / 2.355)^2 to the variance (less at the grid edge).
  EXPECT_NEAR(std::sqrt(w1 * w1 - w0 * w0), 50.0 / 2.3548, 3.0);
}
