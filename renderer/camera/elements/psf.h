// Point spread functions of the lens in the image plane (the optical-image stage, optics.h) and
// their kernels on a pixel grid.
//
// Every PSF here is radially symmetric and tabulated as h(r) per um^2 of the image plane,
// normalised so that its integral over the whole plane is 1:
//   - diffraction of a circular pupil (the Airy pattern; Born & Wolf, Principles of Optics, 8.5.2)
//       h(r) = pi / (4 (lambda N)^2) [2 J1(v) / v]^2,  v = pi r / (lambda N),
//     N the working f-number; its first dark ring is at r = 1.22 lambda N, the encircled energy
//     within r is 1 - J0(v)^2 - J1(v)^2 and its MTF is (2/pi)(acos(x) - x sqrt(1 - x^2)),
//     x = nu lambda N (Goodman, Introduction to Fourier Optics, 6.3);
//   - defocus: that PSF convolved with a uniform disk (pillbox) of the geometric blur circle;
//   - a measured radial MTF table, turned into h(r) by the Hankel transform
//       h(r) = 2 pi integral_0^inf MTF(nu) J0(2 pi nu r) nu dnu.
// A kernel integrates h over each pixel of a grid (supersampled) and is renormalised to sum 1,
// so the part of h beyond the table's extent (the Airy pattern's far rings) is put back into the
// kernel instead of being lost: blurring conserves energy exactly.
#pragma once
#include <vector>

namespace ofl {

struct RadialPsf {
  double dr_um = 0;       // table spacing
  std::vector<double> h;  // h(k dr_um), per um^2; zero beyond the table
  double radius_um() const { return h.empty() ? 0.0 : dr_um * (h.size() - 1); }
  double operator()(double r_um) const;  // linear interpolation
  bool empty() const { return h.empty(); }
};

// The Airy pattern of working f-number `n_w` at `lambda_nm`, tabulated out to
// `extent_lambda_n` x lambda N at 32 samples per lambda N.
RadialPsf airy_psf(double lambda_nm, double n_w, double extent_lambda_n);
// The value of the normalised Airy pattern itself (per um^2), from std::cyl_bessel_j.
double airy_intensity(double r_um, double lambda_nm, double n_w);

// `base` convolved with a uniform disk of diameter `blur_diameter_um` (the defocus blur circle).
// An empty `base` gives the disk alone (no diffraction).
RadialPsf defocus_psf(const RadialPsf& base, double blur_diameter_um);

// h(r) from a radial MTF table (frequencies in cycles/mm, increasing, MTF(0) taken as 1, zero
// beyond the last frequency), out to `extent_um`, sampled at 1 / (8 nu_max) (at most 4097 samples).
RadialPsf psf_from_mtf(const std::vector<double>& freq_cyc_per_mm, const std::vector<double>& mtf, double extent_um);

// A PSF integrated over the pixels of a square grid of pitch `pitch_um`, centred on pixel (0, 0):
// w(dx, dy) = integral over pixel (dx, dy) of h, by `supersample`^2 midpoint samples per pixel
// (raised so that samples are at most `max_sample_um` apart), then divided by the sum.
struct PsfKernel {
  int radius = 0;         // (2 radius + 1)^2 weights
  std::vector<float> w;   // row-major, [(dy + radius) * (2 radius + 1) + dx + radius]
  int size() const { return 2 * radius + 1; }
  float at(int dx, int dy) const { return w[static_cast<size_t>(dy + radius) * size() + dx + radius]; }
  double raw_sum = 0;     // the sum before renormalisation (the table's enclosed energy, ~1)
};
PsfKernel pixel_kernel(const RadialPsf& psf, double pitch_um, int supersample, double max_sample_um);

// A measured PSF image (any shape, not necessarily symmetric): values on a square grid of pitch
// `pitch_um`, the chief ray at the grid's centre ((width - 1) / 2, (height - 1) / 2 in pixel-centre
// coordinates), bilinear between samples and zero outside.
struct PsfImage {
  double wavelength_nm = 0;
  double pitch_um = 1;
  int width = 0, height = 0;
  std::vector<double> v;  // row-major, y down
  double operator()(double x_um, double y_um) const;
};
// The image PSF integrated over the pixels of a grid of pitch `pitch_um` (supersampled so that
// samples are at most half the image's pitch apart), normalised to sum 1.
PsfKernel image_kernel(const PsfImage& psf, double pitch_um, int supersample);
// Discrete convolution of two kernels (the measured PSF with a defocus disk), normalised to sum 1.
PsfKernel convolve_kernels(const PsfKernel& a, const PsfKernel& b);

}  // namespace ofl
