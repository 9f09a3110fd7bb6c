// Colour of the simulated camera for previews and DNG files: the camera's raw response to white
// and a 3x3 matrix from camera RGB to CIE XYZ fitted to the colour-matching functions by least
// squares over wavelength (XYZ(lambda) ~ N * S(lambda), S the channels' spectral sensitivities:
// the Luther-Ives fit, no training reflectances needed). "sensor" colour uses lens x QE only, so
// that what the filter stack does (a 475 nm long-pass turning the image green-red) stays visible in
// the preview; "system" includes the filters.
#pragma once
#include <array>

#include "renderer/camera/description/camera_description.h"

namespace ofl {

using Mat3 = std::array<double, 9>;  // row-major
using Vec3 = std::array<double, 3>;

Mat3 mat3_mul(const Mat3& a, const Mat3& b);
Vec3 mat3_apply(const Mat3& m, const Vec3& v);
Mat3 mat3_inverse(const Mat3& m);  // throws std::domain_error when singular

struct CameraColor {
  Mat3 camera_to_xyz;    // least-squares fit
  Mat3 xyz_to_camera;    // its inverse, scaled so that D65 white (Y = 1) has largest channel 1 (DNG ColorMatrix1)
  Vec3 d65_neutral;      // camera RGB of D65 white through xyz_to_camera (max 1): DNG AsShotNeutral
  Vec3 flat_response;    // electrons-per-photon-weighted response to an equal-energy spectrum (max 1)
};

// Over [lo_nm, hi_nm] intersected with the CIE table (370-730 nm). `include_filters`: see above.
CameraColor camera_color(const CameraDescription& cam, double lo_nm, double hi_nm, bool include_filters);

}  // namespace ofl
