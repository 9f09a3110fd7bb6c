// Photon-transfer analysis of flat-field raw frames in the way of the EMVA 1288 standard (release
// 4.0, "Linear" model): from pairs of frames at a series of exposures it recovers the overall
// system gain K (DN/e-), the temporal dark noise sigma_d (e-) and the saturation capacity
// mu_e.sat (e-); from averages of many frames it recovers DSNU (e-) and PRNU (%).
//   mu_y   = mean over pixels of (A + B) / 2           (per exposure, dark frames likewise)
//   var_y  = var over pixels of (A - B) / 2            (temporal variance; fixed pattern cancels)
//   var_y - var_y.dark = K (mu_y - mu_y.dark)          fitted through the origin over 0-70 % of saturation
//   var_y.dark = K^2 sigma_d^2 + 1/12                  (1/12 DN^2: uniform quantisation noise)
//   mu_y.sat = mu_y at the largest var_y;  mu_e.sat = (mu_y.sat - mu_y.dark) / K
// The variance peaks before the charge reaches full well: shot noise and PRNU carry the brightest
// pixels over first, so mu_e.sat reads below the full well by about two standard deviations of the
// pixel-to-pixel signal spread (1 % PRNU at 40 000 e-: about 3.5 % low). Once every pixel is clipped,
// the plateau (mu_y - mu_y.dark) / K is the full well itself; it is reported as well.
// Spatial non-uniformity from L-frame averages <y>: s^2 = var over pixels of <y> minus var_y / L;
//   DSNU = sqrt(s^2_dark) / K,  PRNU = sqrt(s^2_bright - s^2_dark) / (mu_y.bright - mu_y.dark).
// Used by the tests and benchmarks/camera_bench.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace ofl {

using RawPixels = std::vector<uint16_t>;

struct FramePair {
  RawPixels a, b;  // two frames taken at the same exposure
};

struct PtcPoint {
  double mean_dn = 0;      // mu_y - mu_y.dark
  double variance_dn = 0;  // var_y - var_y.dark
};

struct PhotonTransferResult {
  double system_gain_dn_per_e = 0;   // K
  double read_noise_e = 0;           // sigma_d (includes dark-current shot noise at this exposure)
  double saturation_capacity_e = 0;  // mu_e.sat (EMVA definition)
  double full_well_plateau_e = 0;    // from the brightest pair when its temporal variance has collapsed (< 2 %
                                     //   of the peak: every pixel clipped), else 0
  double dark_mean_dn = 0, dark_variance_dn = 0;
  std::vector<PtcPoint> points;
  int saturation_index = -1;         // index into points of the largest variance
  int fit_points = 0;
};

// `pixels` selects the pixels to use (e.g. one CFA colour); empty means all.
PhotonTransferResult analyse_photon_transfer(const FramePair& dark, const std::vector<FramePair>& series,
                                             const std::vector<size_t>& pixels = {});

struct NonUniformity {
  double dsnu_e = 0;
  double prnu = 0;  // fraction (multiply by 100 for EMVA's percent)
};

// `dark` and `bright` are L frames each (L >= 2), `bright` at about half saturation.
NonUniformity analyse_nonuniformity(const std::vector<RawPixels>& dark, const std::vector<RawPixels>& bright,
                                    double system_gain_dn_per_e, const std::vector<size_t>& pixels = {});

}  // namespace ofl
