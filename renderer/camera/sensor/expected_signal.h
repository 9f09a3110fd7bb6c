// The deterministic half of the camera: spectral radiance -> expected (noise-free) photo-electrons
// per pixel and colour channel,
//   mu_e,c(x, y) = t * A_pixel * fill * pi / (1 + 4 N^2 (1 - m)^2) * cos^4(theta)
//                  * sum_b L_b * integral over band b of T_lens * T_filters(theta) * QE_c * lambda / (h c) dlambda
// with L_b the band-mean radiance of the EXR (W sr^-1 m^-2 nm^-1, constant within its band, the
// best the file allows) and the integral taken finely (<= 0.25 nm steps plus every kink of the
// tables), so a filter edge inside a 10 nm band is resolved. The filter transmittance depends on
// the pixel only through its distance from the optical axis; it is tabulated at 257 radii from the
// centre to the corner (the corner exactly) and interpolated linearly in radius.
#pragma once
#include <string>
#include <vector>

#include "renderer/camera/description/camera_description.h"
#include "renderer/camera/optics/lens_optics.h"
#include "renderer/image/spectral_image.h"

namespace ofl {

struct ResponseTable {
  int bands = 0;
  std::vector<double> radius_px;  // sample radii, uniform from 0 to the corner (one sample when constant)
  std::vector<double> w;          // [(k * 3 + c) * bands + b]: electrons per unit band radiance, cos^4 excluded
  const double* weights(int k, int c) const { return w.data() + (static_cast<size_t>(k) * 3 + c) * bands; }
};

// System quantum efficiency of channel c (electrons per photon reaching the lens): lens
// transmittance x filter stack at the given angles x QE_c.
double system_qe(const CameraDescription& cam, int c, double nm, double aoi_front_rad, double aoi_sensor_rad);

ResponseTable build_response_table(const CameraDescription& cam, const FieldGeometry& g,
                                   const std::vector<double>& band_lo, const std::vector<double>& band_hi);

struct ExpectedSignal {
  int width = 0, height = 0;
  std::vector<float> channel_e;  // [(y * width + x) * 3 + c]: expected photo-electrons channel c would collect
  std::vector<float> mosaic_e;   // [y * width + x]: expected photo-electrons of the pixel's own CFA channel
  double dark_e = 0;             // expected dark electrons per pixel (uniform)
};

ExpectedSignal expected_electrons(const SpectralImage& radiance, const CameraDescription& cam, const FieldGeometry& g);

// Rejects NaN/infinite radiance (InputError naming `file`, the pixel and band) and clips negative
// values to zero (some spectral renderers produce small negatives), reporting how many in `warnings`.
void check_radiance(SpectralImage& radiance, const std::string& file, std::vector<std::string>* warnings);

// Fraction of the on-axis response to a flat radiance spectrum that falls outside the EXR's bands
// (the camera is sensitive where the image has no data), over the QE tables' range.
double response_outside_bands(const CameraDescription& cam, const std::vector<double>& band_lo,
                              const std::vector<double>& band_hi);

}  // namespace ofl
