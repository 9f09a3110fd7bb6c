// Oral tissue presets are calibrated against measurements: the fluorescence they return above
// 480 nm under a 405 nm LED (teeth: 395 nm), as a fraction of what a white Lambertian target
// returns, lies in the range measured on volunteers (oe_tongue_lip; SCIEN teeth data).
#include <gtest/gtest.h>

#include "renderer/core/error.h"
#include "renderer/core/json_node.h"
#include "renderer/render/render_job.h"
#include "renderer/spectral/units.h"

using namespace ofl;

namespace {
// Photons per second per sr per m^2 integrated over [lo, hi] nm, averaged over the image.
double photon_radiance(const SpectralImage& img, double lo, double hi) {
  double s = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int b = 0; b < img.bands(); ++b)
        if (img.band_nm[b] >= lo && img.band_nm[b] <= hi) s += img.pixel(x, y)[b] * photons_per_joule(img.band_nm[b]) * 5.0;
  return s / (img.width * img.height);
}

double fluorescence_ratio(const nlohmann::json& material, double led_nm) {
  auto scene = [&](const nlohmann::json& mat) {
    nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                        {"integrator", {{"spp", 64}, {"max_depth", 1}, {"wavelengths", {{"min_nm", 350}, {"max_nm", 750}, {"step_nm", 5}}},
                                        {"output_bands", {{"min_nm", 370}, {"max_nm", 720}, {"step_nm", 5}}}}},
                        // Spectroradiometer straight above, LED at 45 degrees (no specular highlight in view).
                        {"camera", {{"position", {0, 0, 0.1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 2}, {"resolution", {8, 8}}}},
                        {"materials", {{"m", mat}}},
                        {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.1, 0, 0}}, {"v", {0, 0.1, 0}}, {"material", "m"}}}},
                        {"lights", {{{"spd", {{"type", "gaussian"}, {"peak_nm", led_nm}, {"fwhm_nm", 12}}}, {"radiant_intensity_W_sr", 1.0},
                                     {"position", {0.07, 0, 0.07}}, {"target", {0, 0, 0}}}}}};
    return load_scene(JsonFile::from(j, "tissue_calibration.json"));
  };
  RenderResult t = render(scene(material));
  RenderResult w = render(scene({{"type", "lambertian"}, {"reflectance", 1.0}}));
  return photon_radiance(t.image, 480, 700) / photon_radiance(w.image, 370, 470);
}
}  // namespace

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
