#include "renderer/image/texture.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

namespace {

// The squared distance transform of one periodic line f (f = 0 at the features, infinite elsewhere, or
// the previous pass's squared distances), in place: d[i] = min_j (i - j)^2 + f[j] over the line and
// its copies one period either side (the repeat wrap).
void squared_distance_line(std::vector<double>& f, std::vector<double>& ext, std::vector<int>& v, std::vector<double>& z) {
  const int n = int(f.size()), m = 3 * n;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  ext.assign(size_t(m), kInf);
  for (int i = 0; i < m; ++i) ext[size_t(i)] = f[size_t(i % n)];
  v.assign(size_t(m), 0);
  z.assign(size_t(m) + 1, 0.0);
  int k = -1;
  for (int q = 0; q < m; ++q) {  // the lower envelope of the parabolas (q - x)^2 + ext[q] with finite ext
    if (!std::isfinite(ext[size_t(q)])) continue;
    double s = -kInf;
    while (k >= 0) {
      const int p = v[size_t(k)];
      s = ((ext[size_t(q)] + double(q) * q) - (ext[size_t(p)] + double(p) * p)) / (2.0 * (q - p));
      if (s > z[size_t(k)]) break;
      --k;
    }
    ++k;
    v[size_t(k)] = q;
    z[size_t(k)] = k == 0 ? -kInf : s;
    z[size_t(k) + 1] = kInf;
  }
  if (k < 0) return;  // no feature on the line: f stays infinite
  int j = 0;
  for (int i = 0; i < n; ++i) {
    const double x = double(n + i);  // the middle copy
    while (z[size_t(j) + 1] < x) ++j;
    const double dx = x - v[size_t(j)];
    f[size_t(i)] = dx * dx + ext[size_t(v[size_t(j)])];
  }
}

// The squared distance from every texel to the nearest texel where `feature` holds (periodic).
std::vector<double> squared_distance_to(const Texture& t, const std::vector<char>& feature) {
  const int w = t.width, h = t.height;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> d(size_t(w) * h), line, ext, z;
  std::vector<int> v;
  for (size_t i = 0; i < d.size(); ++i) d[i] = feature[i] ? 0.0 : kInf;
  line.resize(size_t(h));
  for (int x = 0; x < w; ++x) {  // columns, then rows over the columns' result
    for (int y = 0; y < h; ++y) line[size_t(y)] = d[size_t(y) * w + x];
    squared_distance_line(line, ext, v, z);
    for (int y = 0; y < h; ++y) d[size_t(y) * w + x] = line[size_t(y)];
  }
  line.resize(size_t(w));
  for (int y = 0; y < h; ++y) {
    std::copy(d.begin() + ptrdiff_t(y) * w, d.begin() + ptrdiff_t(y + 1) * w, line.begin());
    squared_distance_line(line, ext, v, z);
    std::copy(line.begin(), line.end(), d.begin() + ptrdiff_t(y) * w);
  }
  return d;
}

}  // namespace

std::vector<float> side_distance_texels(const Texture& t, double threshold) {
  const size_t n = t.texels.size();
  // may_be_above / may_be_below: the texels a point's side can come from (both within rounding).
  const double eps = 4.0 * std::numeric_limits<float>::epsilon() * std::max(1.0, std::abs(threshold));
  std::vector<char> above(n), may_be_above(n), may_be_below(n);
  for (size_t i = 0; i < n; ++i) {
    const double v = t.texels[i];
    above[i] = v > threshold;
    may_be_above[i] = v > threshold - eps;
    may_be_below[i] = v <= threshold + eps;
  }
  const std::vector<double> to_above = squared_distance_to(t, may_be_above), to_below = squared_distance_to(t, may_be_below);
  std::vector<float> out(n);
  for (size_t i = 0; i < n; ++i) out[i] = float(std::sqrt(above[i] ? to_below[i] : to_above[i]));
  return out;
}

}  // namespace ofl
