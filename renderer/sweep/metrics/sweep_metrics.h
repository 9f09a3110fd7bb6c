// The numbers a sweep reports for one region of interest (ROI) of one design point, from the
// render's per-pixel planes and the camera's output. Each statistic is a free function on plain
// vectors so that tests can feed images with known answers. Definitions (docs/sweep-format.md):
//  - irradiance non-uniformity over the ROI's pixels (aov.irradiance, LED light only, shadowed):
//    min/max, the robust 5 %/95 % percentile ratio, the coefficient of variation std/mean;
//  - per 2x2 CFA cell whose four pixels are in the ROI: r = R/(R+G+B), g = G/(R+G+B) from the raw
//    (black subtracted; cells with a pixel at the white level are left out, as `oralfluor chroma`
//    does) and noise-free ("_nf") from the expected electrons of every channel averaged over the
//    cell's four pixels (no sensor noise and no CFA sampling: a light gradient across the cell does
//    not bias it); spread = std of r and g and the area pi * a * b of the 95 % ellipse (a, b its
//    semi-axes, chi-square 2 dof);
//  - with two independent renders (different seeds) of the point: the Monte Carlo noise of the
//    noise-free chromaticity ("_mc": std of half the difference of the two renders' r, g, which is
//    the noise of their average) and the spread the light and the tissue cause ("_light": the
//    noise-free covariance minus the Monte Carlo covariance);
//  - intensity = R + G + B of a cell (expected electrons): its CV, and the Pearson correlation of
//    the noise-free r and g with intensity and with the cell's irradiance; slope of r and g per
//    decade of irradiance (least squares against log10 E), which says how far the chromaticity
//    moves when the light changes ten-fold; slope of r and g per 10 degrees of the pixel's field
//    angle (what an interference filter's edge shift does across the image);
//  - shares of the expected photo-electrons in the ROI that are fluorescence, reflected light and
//    leaked excitation (signal_split.h);
//  - SNR per colour channel at the ROI's mean signal from the EMVA 1288 model, and the SNR of the
//    fluorescence in a 2x2 cell (sum of its four pixels) against the noise of the whole signal;
//  - lesion contrast: distance between the lesion's and the healthy ROI's mean (r, g), and that
//    distance over the pooled spread, the Mahalanobis distance with the pooled covariance.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/camera/description/camera_description.h"
#include "renderer/camera/elements/cfa_pattern.h"

namespace ofl {

// --- elementary statistics -------------------------------------------------------------------
double mean_of(const std::vector<double>& x);
double std_of(const std::vector<double>& x);  // sample (n - 1)
// Percentile p in [0, 1] with linear interpolation between order statistics (Hyndman-Fan type 7).
double percentile(std::vector<double> x, double p);
double pearson(const std::vector<double>& x, const std::vector<double>& y);  // NaN when undefined
double ls_slope(const std::vector<double>& x, const std::vector<double>& y);  // dy/dx; NaN when undefined
// Area of the 95 % ellipse of a 2x2 covariance: pi * chi2 * sqrt(det).
double ellipse_area(double c_rr, double c_rg, double c_gg);

struct IrradianceStats {
  size_t pixels = 0;
  double mean = 0, min = 0, max = 0, p5 = 0, p95 = 0, cv = 0, min_over_max = 0, p5_over_p95 = 0;
};
IrradianceStats irradiance_stats(const std::vector<float>& irradiance, const std::vector<uint8_t>& mask);

struct Spread {
  size_t n = 0;
  double mean_r = 0, mean_g = 0, std_r = 0, std_g = 0, cov_rr = 0, cov_rg = 0, cov_gg = 0, area = 0;
};
Spread chroma_spread(const std::vector<std::array<double, 2>>& rg);

struct LesionContrast {
  double distance = 0;     // |mean_lesion - mean_healthy| in (r, g)
  double mahalanobis = 0;  // sqrt(d^T S^-1 d), S the pooled covariance
};
LesionContrast lesion_contrast(const std::vector<std::array<double, 2>>& lesion, const std::vector<std::array<double, 2>>& healthy);

// EMVA 1288 temporal + spatial noise (electrons rms) of a pixel with mean photo-electrons mu:
// shot noise mu, dark shot noise, read noise, DSNU, PRNU * mu and the quantisation noise 1/12 DN^2.
double emva_noise_e(double mu, const SensorDescription& s);
inline double emva_snr(double mu, const SensorDescription& s) { return mu / emva_noise_e(mu, s); }

// --- one ROI of one design point --------------------------------------------------------------
struct CellSample {
  int x = 0, y = 0;                 // top-left pixel
  std::array<double, 2> rg{}, rg_nf{};
  std::array<double, 2> rg_a{}, rg_b{};  // noise-free from each of two independent renders (NaN without)
  double intensity = 0;             // R + G + B of the cell, expected photo-electrons (G = mean of the greens)
  double irradiance = 0;            // mean aov.irradiance of the four pixels
  double field_angle_deg = 0;       // mean field angle of the four pixels (NaN without geometry)
};

// Per-pixel inputs, all width x height, row-major.
struct MetricImages {
  int width = 0, height = 0;
  CfaPattern cfa = CfaPattern::kRGGB;
  double black = 0, white = 65535;
  const std::vector<uint16_t>* raw = nullptr;        // noisy mosaic (DN)
  const std::vector<float>* expected = nullptr;      // expected photo-electrons of the pixel's own channel
  // [(y * width + x) * 3 + c]: expected electrons each channel would collect at the pixel; null:
  // the noise-free chromaticity falls back to the mosaic (`expected`), CFA sampling included.
  const std::vector<float>* channel_e = nullptr;
  const std::vector<float>* channel_e_a = nullptr;   // optional: two independent renders whose
  const std::vector<float>* channel_e_b = nullptr;   // mean is channel_e (Monte Carlo noise)
  const std::vector<float>* irradiance = nullptr;    // aov.irradiance, W m^-2
  const std::vector<float>* field_angle_deg = nullptr;  // optional: chief-ray field angle per pixel
  const std::vector<float>* fluorescence = nullptr;  // signal split (signal_split.h), electrons; optional
  const std::vector<float>* reflected = nullptr;
  const std::vector<float>* leak = nullptr;
};

struct RoiCells {
  std::vector<CellSample> cells;  // cells used (inside the ROI, not saturated, positive signal)
  size_t complete = 0;            // complete cells inside the ROI
  size_t saturated = 0;
};
RoiCells roi_cells(const MetricImages& im, const std::vector<uint8_t>& mask);

// Every metric of one ROI as "name" -> number (null when undefined, e.g. an empty ROI), in the
// order of roi_metric_names().
nlohmann::ordered_json roi_metrics(const MetricImages& im, const std::vector<uint8_t>& mask, const SensorDescription& sensor,
                                   RoiCells* cells_out = nullptr);
const std::vector<std::string>& roi_metric_names();
// Names of the lesion-contrast metrics (prefixed "contrast." in the results).
const std::vector<std::string>& contrast_metric_names();
nlohmann::ordered_json contrast_metrics(const RoiCells& lesion, const RoiCells& healthy);

}  // namespace ofl
