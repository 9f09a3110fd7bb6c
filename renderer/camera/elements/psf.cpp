#include "renderer/camera/elements/psf.h"

#include <algorithm>
#include <cmath>

#include "renderer/spectral/spectra/units.h"

namespace ofl {

double RadialPsf::operator()(double r) const {
  if (h.empty()) return 0.0;
  double u = std::max(r, 0.0) / dr_um;
  if (u >= static_cast<double>(h.size() - 1)) return u == static_cast<double>(h.size() - 1) ? h.back() : 0.0;
  size_t k = static_cast<size_t>(u);
  double f = u - k;
  return (1.0 - f) * h[k] + f * h[k + 1];
}

double airy_intensity(double r_um, double lambda_nm, double n_w) {
  double ln = lambda_nm * 1e-3 * n_w;  // lambda N in um
  double v = kPi * r_um / ln;
  double a = v < 1e-8 ? 1.0 : 2.0 * std::cyl_bessel_j(1.0, v) / v;
  return kPi / (4.0 * ln * ln) * a * a;
}

RadialPsf airy_psf(double lambda_nm, double n_w, double extent_lambda_n) {
  constexpr int kPerLambdaN = 32;
  double ln = lambda_nm * 1e-3 * n_w;
  RadialPsf p;
  p.dr_um = ln / kPerLambdaN;
  int n = static_cast<int>(std::ceil(extent_lambda_n * kPerLambdaN)) + 1;
  p.h.resize(n);
  for (int k = 0; k < n; ++k) p.h[k] = airy_intensity(k * p.dr_um, lambda_nm, n_w);
  return p;
}

namespace {

// Angular measure (0..2 pi) of the circle of radius s about a point at distance r from the centre
// of a disk of radius R that lies inside the disk.
double angle_inside_disk(double r, double s, double R) {
  if (s <= 0) return r <= R ? 2.0 * kPi : 0.0;
  if (r <= 0) return s <= R ? 2.0 * kPi : 0.0;
  double c = (R * R - r * r - s * s) / (2.0 * r * s);
  if (c >= 1) return 2.0 * kPi;
  if (c <= -1) return 0.0;
  return 2.0 * (kPi - std::acos(c));
}

RadialPsf pillbox(double R) {
  RadialPsf p;
  constexpr int kSamples = 256;
  p.dr_um = R / kSamples;
  p.h.assign(kSamples + 1, 1.0 / (kPi * R * R));
  return p;
}

}  // namespace

RadialPsf defocus_psf(const RadialPsf& base, double blur_diameter_um) {
  double R = 0.5 * blur_diameter_um;
  if (base.empty()) return pillbox(R);
  if (R < 0.5 * base.dr_um) return base;
  // h(r) = 1 / (pi R^2) * integral over the disk of base(|r - s|) = 1 / (pi R^2) integral_0^smax base(s) s theta_in(r, s) ds
  double smax = base.radius_um();
  RadialPsf p;
  p.dr_um = std::max(base.dr_um, (R + smax) / 512.0);
  int n = static_cast<int>(std::ceil((R + smax) / p.dr_um)) + 1;
  p.h.resize(n);
  const double norm = 1.0 / (kPi * R * R);
  // Trapezoid weights w_j base(s_j) s_j and their prefix sums: where the circle of radius s lies
  // wholly inside the disk (s <= R - r) the angle is 2 pi, wholly outside it is 0; only the
  // samples between need the angle.
  const size_t m = base.h.size();
  std::vector<double> a(m), prefix(m + 1, 0.0);
  for (size_t j = 0; j < m; ++j) {
    double w = (j == 0 || j + 1 == m) ? 0.5 : 1.0;
    a[j] = w * base.h[j] * j * base.dr_um;
    prefix[j + 1] = prefix[j] + a[j];
  }
  auto index_above = [&](double s) {  // first sample index with s_j > s
    if (s < 0) return size_t{0};
    return std::min(m, static_cast<size_t>(std::floor(s / base.dr_um)) + 1);
  };
  for (int k = 0; k < n; ++k) {
    double r = k * p.dr_um;
    size_t inside_end = r < R ? index_above(R - r) : 0;   // samples [0, inside_end) wholly inside
    size_t partial_begin = r < R ? inside_end : index_above(r - R);
    size_t partial_end = index_above(R + r);
    double sum = 2.0 * kPi * prefix[inside_end];
    for (size_t j = partial_begin; j < partial_end; ++j) sum += a[j] * angle_inside_disk(r, j * base.dr_um, R);
    p.h[k] = norm * sum * base.dr_um;
  }
  return p;
}

RadialPsf psf_from_mtf(const std::vector<double>& freq, const std::vector<double>& mtf, double extent_um) {
  double numax = freq.back() * 1e-3;  // cycles per um
  constexpr int kNu = 2000;
  RadialPsf p;
  p.dr_um = std::max(1.0 / (8.0 * numax), extent_um / 4096.0);  // at most 4097 samples whatever the table's range
  int n = static_cast<int>(std::ceil(extent_um / p.dr_um)) + 1;
  p.h.resize(n);
  // MTF on a uniform frequency grid (piecewise linear in the table, 1 at 0).
  std::vector<double> nu(kNu + 1), m(kNu + 1);
  for (int i = 0; i <= kNu; ++i) {
    double f = numax * i / kNu * 1e3;  // cycles per mm
    nu[i] = numax * i / kNu;
    auto it = std::upper_bound(freq.begin(), freq.end(), f);
    double f0 = 0, m0 = 1, f1, m1;
    if (it == freq.end()) {
      m[i] = mtf.back();
      continue;
    }
    size_t j = static_cast<size_t>(it - freq.begin());
    f1 = freq[j];
    m1 = mtf[j];
    if (j > 0) {
      f0 = freq[j - 1];
      m0 = mtf[j - 1];
    }
    m[i] = f1 > f0 ? m0 + (m1 - m0) * (f - f0) / (f1 - f0) : m1;
  }
  double dnu = numax / kNu;
  for (int k = 0; k < n; ++k) {
    double r = k * p.dr_um, sum = 0;
    for (int i = 0; i <= kNu; ++i) {
      double w = (i == 0 || i == kNu) ? 0.5 : 1.0;
      sum += w * m[i] * std::cyl_bessel_j(0.0, 2.0 * kPi * nu[i] * r) * nu[i];
    }
    p.h[k] = 2.0 * kPi * sum * dnu;
  }
  return p;
}

PsfKernel pixel_kernel(const RadialPsf& psf, double pitch, int supersample, double max_sample_um) {
  PsfKernel k;
  k.radius = static_cast<int>(std::ceil(psf.radius_um() / pitch + 0.5));
  int S = std::max(supersample, static_cast<int>(std::ceil(pitch / max_sample_um)));
  S = std::min(S, 256);
  int n = k.size();
  k.w.assign(static_cast<size_t>(n) * n, 0.0f);
  const double sub = pitch / S, area = sub * sub;
  std::vector<double> w(k.w.size(), 0.0);
  // The PSF is symmetric in x, y and the diagonal: integrate one octant (0 <= dy <= dx) and mirror.
  for (int dy = 0; dy <= k.radius; ++dy)
    for (int dx = dy; dx <= k.radius; ++dx) {
      double sum = 0;
      for (int b = 0; b < S; ++b) {
        double y = (dy - 0.5 + (b + 0.5) / S) * pitch;
        for (int a = 0; a < S; ++a) {
          double x = (dx - 0.5 + (a + 0.5) / S) * pitch;
          sum += psf(std::sqrt(x * x + y * y));
        }
      }
      sum *= area;
      for (int sx : {-1, 1})
        for (int sy : {-1, 1}) {
          w[static_cast<size_t>(sy * dy + k.radius) * n + sx * dx + k.radius] = sum;
          w[static_cast<size_t>(sx * dx + k.radius) * n + sy * dy + k.radius] = sum;
        }
    }
  double total = 0;
  for (double v : w) total += v;
  k.raw_sum = total;
  for (size_t i = 0; i < w.size(); ++i) k.w[i] = static_cast<float>(total > 0 ? w[i] / total : 0.0);
  return k;
}

double PsfImage::operator()(double x_um, double y_um) const {
  double u = x_um / pitch_um + 0.5 * (width - 1), w = y_um / pitch_um + 0.5 * (height - 1);
  int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(w));
  double fx = u - x0, fy = w - y0;
  auto at = [&](int x, int y) {
    return (x < 0 || y < 0 || x >= width || y >= height) ? 0.0 : v[static_cast<size_t>(y) * width + x];
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) + fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

PsfKernel image_kernel(const PsfImage& psf, double pitch, int supersample) {
  PsfKernel k;
  double half_um = 0.5 * std::max(psf.width, psf.height) * psf.pitch_um;
  k.radius = static_cast<int>(std::ceil(half_um / pitch + 0.5));
  int S = std::min(256, std::max(supersample, static_cast<int>(std::ceil(2.0 * pitch / psf.pitch_um))));
  int n = k.size();
  S = std::max(1, std::min(S, 8192 / n));  // at most 8192^2 samples in all
  std::vector<double> w(static_cast<size_t>(n) * n, 0.0);
  double total = 0;
  for (int dy = -k.radius; dy <= k.radius; ++dy)
    for (int dx = -k.radius; dx <= k.radius; ++dx) {
      double sum = 0;
      for (int b = 0; b < S; ++b)
        for (int a = 0; a < S; ++a)
          sum += psf((dx - 0.5 + (a + 0.5) / S) * pitch, (dy - 0.5 + (b + 0.5) / S) * pitch);
      w[static_cast<size_t>(dy + k.radius) * n + dx + k.radius] = sum;
      total += sum;
    }
  k.raw_sum = total * (pitch / S) * (pitch / S);
  k.w.resize(w.size());
  for (size_t i = 0; i < w.size(); ++i) k.w[i] = static_cast<float>(total > 0 ? w[i] / total : 0.0);
  return k;
}

PsfKernel convolve_kernels(const PsfKernel& a, const PsfKernel& b) {
  PsfKernel k;
  k.radius = a.radius + b.radius;
  int n = k.size();
  std::vector<double> w(static_cast<size_t>(n) * n, 0.0);
  for (int ay = -a.radius; ay <= a.radius; ++ay)
    for (int ax = -a.radius; ax <= a.radius; ++ax) {
      double va = a.at(ax, ay);
      if (va == 0) continue;
      for (int by = -b.radius; by <= b.radius; ++by)
        for (int bx = -b.radius; bx <= b.radius; ++bx)
          w[static_cast<size_t>(ay + by + k.radius) * n + ax + bx + k.radius] += va * b.at(bx, by);
    }
  double total = 0;
  for (double v : w) total += v;
  k.raw_sum = 1;
  k.w.resize(w.size());
  for (size_t i = 0; i < w.size(); ++i) k.w[i] = static_cast<float>(total > 0 ? w[i] / total : 0.0);
  return k;
}

}  // namespace ofl
