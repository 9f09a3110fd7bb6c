#include "renderer/camera/raw/camera_color.h"

#include <Eigen/Dense>

#include <algorithm>
#include <stdexcept>

#include "renderer/camera/sensor/expected_signal.h"
#include "renderer/spectral/color.h"

namespace ofl {

Mat3 mat3_mul(const Mat3& a, const Mat3& b) {
  Mat3 r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) r[i * 3 + j] += a[i * 3 + k] * b[k * 3 + j];
  return r;
}

Vec3 mat3_apply(const Mat3& m, const Vec3& v) {
  return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
          m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}

Mat3 mat3_inverse(const Mat3& m) {
  Eigen::Matrix3d e;
  for (int i = 0; i < 9; ++i) e(i / 3, i % 3) = m[i];
  double det = e.determinant();
  if (!(std::abs(det) > 1e-300)) throw std::domain_error("singular 3x3 matrix");
  Eigen::Matrix3d inv = e.inverse();
  Mat3 r;
  for (int i = 0; i < 9; ++i) r[i] = inv(i / 3, i % 3);
  return r;
}

CameraColor camera_color(const CameraDescription& cam, double lo, double hi, bool include_filters) {
  lo = std::max(lo, 370.0);
  hi = std::min(hi, 730.0);
  if (!(hi > lo + 10)) {  // the image's bands miss the visible range: use all of it
    lo = 370.0;
    hi = 730.0;
  }
  WavelengthGrid grid{lo, lo + std::floor(hi - lo), 1.0};
  ColorMatching cmf = cie1931_on_grid(grid);
  int n = grid.size();
  Eigen::MatrixXd S(3, n), C(3, n);
  CameraColor out;
  out.flat_response = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    double nm = grid.wavelength(i);
    for (int c = 0; c < 3; ++c) {
      double q = include_filters ? system_qe(cam, c, nm, 0, 0) : cam.lens.transmittance(nm) * cam.sensor.qe[c](nm);
      // Sensitivity to energy: electrons per joule ~ QE * lambda.
      S(c, i) = q * nm;
      out.flat_response[c] += q * nm;
    }
    C(0, i) = cmf.x[i];
    C(1, i) = cmf.y[i];
    C(2, i) = cmf.z[i];
  }
  double fmax = std::max({out.flat_response[0], out.flat_response[1], out.flat_response[2], 1e-300});
  for (double& v : out.flat_response) v /= fmax;
  // XYZ ~ N S  =>  N = C S^T (S S^T)^-1.
  Eigen::Matrix3d SSt = S * S.transpose();
  Eigen::Matrix3d N = (C * S.transpose()) * SSt.completeOrthogonalDecomposition().pseudoInverse();
  for (int i = 0; i < 9; ++i) out.camera_to_xyz[i] = N(i / 3, i % 3);
  Mat3 m;
  try {
    m = mat3_inverse(out.camera_to_xyz);
  } catch (const std::domain_error&) {
    m = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    out.camera_to_xyz = m;
  }
  Vec3 white = mat3_apply(m, {0.95047, 1.0, 1.08883});
  double wmax = std::max({white[0], white[1], white[2], 1e-300});
  for (double& v : m) v /= wmax;
  for (double& v : white) v = std::max(v / wmax, 1e-6);
  out.xyz_to_camera = m;
  out.d65_neutral = white;
  return out;
}

}  // namespace ofl
