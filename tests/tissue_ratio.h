// The calibration measurement of oral tissue presets (tests/test_tissue.cpp, test_layered_presets.cpp):
// a spectroradiometer straight above a flat patch, an LED at 45 degrees, the fluorescence photon
// radiance above 480 nm as a fraction of what a white Lambertian target returns at the LED.
#pragma once
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/core/files/json_node.h"
#include "renderer/render/render_job.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl::test {

// Photons per second per sr per m^2 integrated over [lo, hi] nm, averaged over the image.
inline double photon_radiance(const SpectralImage& img, double lo, double hi) {
  double s = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int b = 0; b < img.bands(); ++b)
        if (img.band_nm[b] >= lo && img.band_nm[b] <= hi) s += img.pixel(x, y)[b] * photons_per_joule(img.band_nm[b]) * 5.0;
  return s / (img.width * img.height);
}

inline Scene patch_scene(const nlohmann::json& material, double led_nm, int spp) {
  nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                      {"integrator", {{"spp", spp}, {"max_depth", 1}, {"wavelengths", {{"min_nm", 350}, {"max_nm", 750}, {"step_nm", 5}}},
                                      {"output_bands", {{"min_nm", 370}, {"max_nm", 720}, {"step_nm", 5}}}}},
                      // Spectroradiometer straight above, LED at 45 degrees (no specular highlight in view).
                      {"camera", {{"position", {0, 0, 0.1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 2}, {"resolution", {8, 8}}}},
                      {"materials", {{"m", material}}},
                      {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.1, 0, 0}}, {"v", {0, 0.1, 0}}, {"material", "m"}}}},
                      {"lights", {{{"spd", {{"type", "gaussian"}, {"peak_nm", led_nm}, {"fwhm_nm", 12}}}, {"radiant_intensity_W_sr", 1.0},
                                   {"position", {0.07, 0, 0.07}}, {"target", {0, 0, 0}}}}}};
  return load_scene(JsonFile::from(j, "tissue_calibration.json"));
}

// The white target's photon radiance around the LED (370-470 nm).
inline double white_radiance(double led_nm) {
  return photon_radiance(render(patch_scene({{"type", "lambertian"}, {"reflectance", 1.0}}, led_nm, 16)).image, 370, 470);
}

// Fluorescence above 480 nm over the white target's return around the LED.
inline double fluorescence_ratio(const nlohmann::json& material, double led_nm, int spp = 64) {
  return photon_radiance(render(patch_scene(material, led_nm, spp)).image, 480, 700) / white_radiance(led_nm);
}

// The same ratio in several wavelength ranges {lo, hi} of one render.
inline std::vector<double> fluorescence_ratios(const nlohmann::json& material, double led_nm, int spp,
                                               const std::vector<std::pair<double, double>>& ranges) {
  SpectralImage img = render(patch_scene(material, led_nm, spp)).image;
  double w = white_radiance(led_nm);
  std::vector<double> r;
  for (auto [lo, hi] : ranges) r.push_back(photon_radiance(img, lo, hi) / w);
  return r;
}

}  // namespace ofl::test
