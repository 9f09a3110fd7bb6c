#include "renderer/image/png_writer.h"

#include <algorithm>
#include <cmath>

#include "renderer/image/image_file.h"
#include "renderer/spectral/color.h"

namespace ofl {

namespace {

std::vector<unsigned char> srgb_pixels(const std::vector<float>& rgb, double exposure) {
  std::vector<unsigned char> px(rgb.size());
  for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<unsigned char>(std::lround(255.0 * srgb_encode(rgb[i] * exposure)));
  return px;
}

OIIO::ImageSpec srgb_spec(int w, int h) {
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  return spec;
}

}  // namespace

void write_srgb_png(const std::filesystem::path& file, int w, int h, const std::vector<float>& rgb, double exposure) {
  write_image_file(file, srgb_spec(w, h), srgb_pixels(rgb, exposure).data());
}

std::string srgb_png_bytes(int w, int h, const std::vector<float>& rgb, double exposure) {
  return encode_image_file("image.png", srgb_spec(w, h), srgb_pixels(rgb, exposure).data());
}

double auto_exposure(const std::vector<float>& rgb, double percentile, double target) {
  std::vector<float> lum;
  lum.reserve(rgb.size() / 3);
  for (size_t i = 0; i + 2 < rgb.size(); i += 3) {
    float y = 0.2126f * rgb[i] + 0.7152f * rgb[i + 1] + 0.0722f * rgb[i + 2];
    if (std::isfinite(y) && y > 0) lum.push_back(y);
  }
  if (lum.empty()) return 1.0;
  size_t k = std::min(lum.size() - 1, static_cast<size_t>(percentile * lum.size()));
  std::nth_element(lum.begin(), lum.begin() + k, lum.end());
  return lum[k] > 0 ? target / lum[k] : 1.0;
}

}  // namespace ofl
