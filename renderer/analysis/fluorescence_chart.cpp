#include "renderer/analysis/fluorescence_chart.h"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "renderer/core/files/asset_path.h"
#include "renderer/spectral/chromophores/fluorophore_library.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {

Spectrum example_led_spectrum() {
  return table_spectrum(read_spectrum_csv(asset_path("spectra/lights/oraleye_405nm_flood.csv")), "OralEye 405 nm flood");
}

Spectrum tongue_reflectance_spectrum() {
  SpectrumCsvOptions o;
  o.outside = Outside::kClamp;
  return table_spectrum(read_spectrum_csv(asset_path("spectra/tissue/tongue_reflectance.csv"), o), "tongue");
}

SpectralImage make_fluorescence_chart(const ChartOptions& o) {
  std::vector<double> bands = o.band_nm;
  if (bands.empty())
    for (double nm = 400; nm <= 700 + 1e-9; nm += 10) bands.push_back(nm);
  SpectralImage img;
  int rows = static_cast<int>(o.fluorophores.size()), cols = static_cast<int>(o.concentrations.size());
  img.resize(cols * o.patch_px, std::max(rows, 1) * o.patch_px, bands);
  auto lo = img.band_lo(), hi = img.band_hi();

  double gmin = lo.front(), gmax = hi.back();
  if (o.led.kinks.size() >= 2) {
    gmin = std::min(gmin, o.led.kinks.front());
    gmax = std::max(gmax, o.led.kinks.back());
  }
  double step = o.transport_step_nm;
  gmin = std::floor(gmin / step) * step;
  gmax = gmin + std::ceil((gmax - gmin) / step) * step;
  WavelengthGrid grid{gmin, gmax, step};
  int n = grid.size();
  std::vector<double> E = tabulate(o.led, grid);
  double peak = *std::max_element(E.begin(), E.end());
  for (double& v : E) v *= peak > 0 ? o.peak_irradiance / peak : 0.0;
  std::vector<double> Eq(n), R = tabulate(o.reflectance, grid);
  for (int i = 0; i < n; ++i) Eq[i] = E[i] * photons_per_joule(grid.wavelength(i));

  // Band-mean radiance of every patch, before shading.
  std::vector<std::vector<double>> patch(static_cast<size_t>(std::max(rows, 1)) * cols);
  for (int r = 0; r < std::max(rows, 1); ++r) {
    GridEem eem;
    std::vector<double> fl(n, 0.0);
    if (rows > 0) {
      eem = load_fluorophore(o.fluorophores[r], grid);
      fl = eem.apply(Eq);  // photons s^-1 m^-2 nm^-1 per unit concentration
    }
    for (int c = 0; c < cols; ++c) {
      std::vector<double> L(n);
      for (int i = 0; i < n; ++i)
        L[i] = (R[i] * E[i] + o.concentrations[c] * fl[i] * photon_energy_J(grid.wavelength(i))) / kPi;
      std::vector<double> band(bands.size(), 0.0);
      for (size_t b = 0; b < bands.size(); ++b) {
        // Bin mean of the grid values overlapping [lo, hi] (weights = overlap).
        double sum = 0, wsum = 0;
        for (int i = 0; i < n; ++i) {
          double ov = std::min(hi[b], grid.bin_hi(i)) - std::max(lo[b], grid.bin_lo(i));
          if (ov > 0) {
            sum += L[i] * ov;
            wsum += ov;
          }
        }
        band[b] = wsum > 0 ? sum / wsum : 0.0;
      }
      patch[static_cast<size_t>(r) * cols + c] = band;
    }
  }
  double cx = 0.5 * img.width, cy = 0.5 * img.height, rmax2 = cx * cx + cy * cy;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
      double shade = 1.0 - (1.0 - o.shading_corner) * (dx * dx + dy * dy) / rmax2;
      const auto& band = patch[static_cast<size_t>(y / o.patch_px) * cols + x / o.patch_px];
      float* p = img.pixel(x, y);
      for (size_t b = 0; b < bands.size(); ++b) p[b] = static_cast<float>(shade * band[b]);
    }

  nlohmann::json spd = {{"nm", nlohmann::json::array()}, {"W_per_sr_nm", nlohmann::json::array()}};
  for (int i = 0; i < n; ++i) {
    spd["nm"].push_back(grid.wavelength(i));
    spd["W_per_sr_nm"].push_back(E[i]);
  }
  img.attributes["oralfluor.vfov_deg"] = std::to_string(o.vfov_deg);
  img.attributes["oralfluor.scene"] = "synthetic fluorescence chart";
  img.attributes["oralfluor.excitation_spd"] = spd.dump();
  img.attributes["oralfluor.chart"] =
      nlohmann::json{{"rows", o.fluorophores}, {"concentrations", o.concentrations}, {"patch_px", o.patch_px},
                     {"shading_corner", o.shading_corner}, {"peak_irradiance_W_m2_nm", o.peak_irradiance}}
          .dump();
  return img;
}

}  // namespace ofl
