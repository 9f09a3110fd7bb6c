#include "renderer/spectral/spectra/sample_shapes.h"

#include <algorithm>
#include <cmath>

namespace ofl {

void gaussian_blur(std::vector<double>& v, double step, double fwhm) {
  double sigma = fwhm / (2.0 * std::sqrt(2.0 * std::log(2.0))) / step;  // in samples
  if (!(sigma > 0.05)) return;
  int half = static_cast<int>(std::ceil(4 * sigma));
  std::vector<double> k(2 * half + 1);
  for (int i = -half; i <= half; ++i) k[i + half] = std::exp(-0.5 * (i / sigma) * (i / sigma));
  int n = static_cast<int>(v.size());
  std::vector<double> out(n);
  for (int i = 0; i < n; ++i) {
    double s = 0, w = 0;
    for (int j = std::max(0, i - half); j <= std::min(n - 1, i + half); ++j) {
      s += k[j - i + half] * v[j];
      w += k[j - i + half];
    }
    out[i] = s / w;
  }
  v.swap(out);
}

void shift_samples(std::vector<double>& v, double step, double delta) {
  if (delta == 0 || v.empty()) return;
  // Cubic (Catmull-Rom) interpolation: a linear one would also blur sharp features such as the
  // long-pass edge by up to half a grid step, which the fit then "explains" with other causes.
  const int n = static_cast<int>(v.size());
  auto at = [&](int i) { return v[std::clamp(i, 0, n - 1)]; };
  std::vector<double> out(n);
  const double d = delta / step;
  for (int i = 0; i < n; ++i) {
    double x = i - d;
    if (x <= 0) { out[i] = v[0]; continue; }
    if (x >= n - 1) { out[i] = v[n - 1]; continue; }
    int a = static_cast<int>(x);
    double t = x - a, p0 = at(a - 1), p1 = at(a), p2 = at(a + 1), p3 = at(a + 2);
    out[i] = p1 + 0.5 * t * (p2 - p0 + t * (2 * p0 - 5 * p1 + 4 * p2 - p3 + t * (3 * (p1 - p2) + p3 - p0)));
  }
  v.swap(out);
}

}  // namespace ofl
