#include "renderer/camera/raw/raw_preview.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "renderer/image/png_writer.h"

namespace ofl {

std::vector<float> demosaic_bilinear(const std::vector<uint16_t>& dn, int w, int h, CfaPattern cfa, double black,
                                     double white) {
  std::vector<float> rgb(static_cast<size_t>(w) * h * 3, 0.0f);
  double scale = 1.0 / std::max(white - black, 1.0);
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < w; ++x) {
        double sum[3] = {0, 0, 0};
        int count[3] = {0, 0, 0};
        int own = cfa_channel(cfa, x, y);
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
            int c = cfa_channel(cfa, xx, yy);
            if (c == own && (dx != 0 || dy != 0)) continue;  // the pixel's own colour is measured
            sum[c] += dn[static_cast<size_t>(yy) * w + xx];
            ++count[c];
          }
        size_t o = (static_cast<size_t>(y) * w + x) * 3;
        for (int c = 0; c < 3; ++c)
          rgb[o + c] = count[c] ? static_cast<float>((sum[c] / count[c] - black) * scale) : 0.0f;
      }
  });
  return rgb;
}

bool parse_white_balance(const std::string& s, WhiteBalance* wb) {
  if (s == "sensor") *wb = WhiteBalance::kSensor;
  else if (s == "gray" || s == "grey") *wb = WhiteBalance::kGray;
  else if (s == "none") *wb = WhiteBalance::kNone;
  else return false;
  return true;
}

std::vector<float> raw_to_linear_srgb(const std::vector<uint16_t>& dn, int w, int h, CfaPattern cfa, double black,
                                      double white, const CameraColor& col, const PreviewSettings& st,
                                      Vec3* gains_used) {
  std::vector<float> rgb = demosaic_bilinear(dn, w, h, cfa, black, white);
  // Camera RGB -> XYZ -> linear sRGB. camera_to_xyz maps the camera's response to D65 white onto
  // D65 white, so "sensor" needs no further gains; gray world first scales each channel so that the
  // image mean becomes that neutral; "none" shows camera RGB as it is.
  const Mat3 xyz_to_srgb = {3.2404542, -1.5371385, -0.4985314, -0.9692660, 1.8760108,
                            0.0415560, 0.0556434,  -0.2040259, 1.0572252};
  Vec3 gains = {1, 1, 1};
  Mat3 m = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  if (st.white_balance != WhiteBalance::kNone) {
    m = mat3_mul(xyz_to_srgb, mat3_inverse(col.xyz_to_camera));
    if (st.white_balance == WhiteBalance::kGray) {
      Vec3 mean = {0, 0, 0};
      for (size_t i = 0; i < rgb.size(); ++i) mean[i % 3] += std::max(0.0f, rgb[i]);
      for (int c = 0; c < 3; ++c) gains[c] = mean[c] > 0 ? col.d65_neutral[c] / mean[c] : 1.0;
      double gmin = std::min({gains[0], gains[1], gains[2]});
      for (double& g : gains) g /= gmin;
    }
  }
  if (gains_used) *gains_used = gains;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rgb.size() / 3), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t p = r.begin(); p != r.end(); ++p) {
      Vec3 cam = {rgb[p * 3] * gains[0], rgb[p * 3 + 1] * gains[1], rgb[p * 3 + 2] * gains[2]};
      Vec3 out = mat3_apply(m, cam);
      for (int c = 0; c < 3; ++c) rgb[p * 3 + c] = static_cast<float>(std::max(0.0, out[c]));
    }
  });
  return rgb;
}

void write_raw_preview_png(const std::filesystem::path& file, const std::vector<uint16_t>& dn, int w, int h,
                           CfaPattern cfa, double black, double white, const CameraColor& col,
                           const PreviewSettings& st) {
  std::vector<float> rgb = raw_to_linear_srgb(dn, w, h, cfa, black, white, col, st);
  double exposure = st.auto_exposure ? auto_exposure(rgb, 0.99, 0.9) : 1.0;
  write_srgb_png(file, w, h, rgb, exposure);
}

}  // namespace ofl
