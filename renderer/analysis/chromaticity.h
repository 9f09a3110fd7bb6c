// Chromaticity of a raw Bayer mosaic, the measure the reference paper (Farrell et al., OralEye)
// uses because it does not depend on how strongly a spot is lit: per 2x2 CFA cell
//   r = R / (R + G + B),  g = G / (R + G + B),  G = mean of the cell's two greens,
// from black-level-subtracted raw values; then the mean, covariance and 95 % ellipse of the cells
// in a region of interest. The ellipse is the region that holds 95 % of the cells if (r, g) is
// bivariate normal: semi-axes sqrt(5.991 * eigenvalue) of the covariance (chi-square, 2 dof).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/camera/elements/cfa_pattern.h"

namespace ofl {

struct Roi {
  int x = 0, y = 0, w = 0, h = 0;
};
// "x,y,w,h" with w, h > 0; false when malformed.
bool parse_roi(const std::string& s, Roi* roi);

struct Ellipse {
  double cx = 0, cy = 0;   // centre (r, g)
  double a = 0, b = 0;     // semi-axes, a >= b
  double angle_rad = 0;    // of the major axis from the r axis
};
constexpr double kChiSquare2Dof95 = 5.991464547107979;
Ellipse covariance_ellipse(double cx, double cy, double c_rr, double c_rg, double c_gg, double chi2 = kChiSquare2Dof95);

// r, g of a cell; {nan, nan} when R + G + B <= 0.
std::array<double, 2> rg_chromaticity(double R, double G, double B);

struct ChromaStats {
  Roi roi;
  size_t cells = 0;        // complete 2x2 cells (aligned to the CFA period) inside the ROI
  size_t used = 0;         // cells that entered the statistics
  size_t saturated = 0;    // cells with a value at the white level (left out unless asked)
  size_t nonpositive = 0;  // cells with R + G + B <= 0 after black subtraction (left out)
  std::vector<std::array<double, 2>> rg;  // per used cell
  std::array<double, 3> mean_rgb = {0, 0, 0};  // mean black-subtracted R, G, B (DN) of used cells
  double mean_r = 0, mean_g = 0;
  double cov_rr = 0, cov_rg = 0, cov_gg = 0;  // sample covariance (n - 1)
  Ellipse ellipse95;
  nlohmann::json to_json(bool with_points = false) const;
};

// Throws InputError (field "--roi") when the ROI leaves the image or holds no complete cell.
// With a `mask` (one byte per pixel), only cells whose four pixels are all non-zero in it count
// (e.g. the pixels that see the tongue, from the render's aov.material plane).
ChromaStats roi_chromaticity(const std::vector<uint16_t>& dn, int width, int height, CfaPattern cfa, double black,
                             double white, const Roi& roi, bool include_saturated = false,
                             const std::vector<uint8_t>* mask = nullptr);

}  // namespace ofl
