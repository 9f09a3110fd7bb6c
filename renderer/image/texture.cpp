#include "renderer/image/texture.h"

#include <cmath>

#include "renderer/core/errors/error.h"
#include "renderer/image/image_file.h"

namespace ofl {

float Texture::lookup(float u, float v) const {
  // glTF UV: (0,0) is the top-left of the image, v grows downward.
  float x = (u - std::floor(u)) * width - 0.5f;
  float y = (v - std::floor(v)) * height - 0.5f;
  int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  float fx = x - x0, fy = y - y0;
  auto at = [&](int xi, int yi) {
    xi = ((xi % width) + width) % width;
    yi = ((yi % height) + height) % height;
    return texels[static_cast<size_t>(yi) * width + xi];
  };
  return (at(x0, y0) * (1 - fx) + at(x0 + 1, y0) * fx) * (1 - fy) + (at(x0, y0 + 1) * (1 - fx) + at(x0 + 1, y0 + 1) * fx) * fy;
}

Texture read_texture(const std::filesystem::path& file) {
  FloatImage im = read_image_file(file);
  Texture t;
  t.file = file.string();
  t.width = im.width;
  t.height = im.height;
  const int nc = im.channels;
  const std::vector<float>& px = im.pixels;
  t.texels.resize(static_cast<size_t>(t.width) * t.height);
  for (size_t i = 0; i < t.texels.size(); ++i) {
    float v = nc >= 3 ? 0.2126f * px[i * nc] + 0.7152f * px[i * nc + 1] + 0.0722f * px[i * nc + 2] : px[i * nc];
    if (!std::isfinite(v) || v < 0) throw InputError(file.string(), "pixel " + std::to_string(i), "texture value is negative or not finite");
    t.texels[i] = v;
  }
  return t;
}

}  // namespace ofl
