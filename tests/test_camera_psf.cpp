// The lens PSFs of the optical-image stage (renderer/camera/elements/psf.h) against closed forms:
// encircled energy of the Airy pattern, the diffraction MTF of a circular pupil computed from the
// pixel kernel's Fourier transform, the pillbox (defocus) MTF, and a PSF rebuilt from an MTF table.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "renderer/camera/elements/psf.h"

using namespace ofl;

namespace {
constexpr double kPiT = 3.14159265358979323846;

// Diffraction-limited MTF of a circular pupil at x = nu lambda N (Goodman 6.3).
double mtf_circular(double x) {
  if (x >= 1) return 0;
  return 2.0 / kPiT * (std::acos(x) - x * std::sqrt(1 - x * x));
}
double sinc(double x) { return std::fabs(x) < 1e-12 ? 1.0 : std::sin(kPiT * x) / (kPiT * x); }
// MTF of a uniform disk of diameter D at frequency nu: 2 J1(pi D nu) / (pi D nu).
double mtf_disk(double D, double nu) {
  double a = kPiT * D * nu;
  return a < 1e-12 ? 1.0 : 2.0 * std::cyl_bessel_j(1.0, a) / a;
}

// Transfer function of a pixel kernel along x at frequency nu (cycles/um): the DFT of its line
// spread function (the kernel summed over y). The kernel is symmetric, so the DFT is real.
double kernel_transfer(const PsfKernel& k, double pitch_um, double nu) {
  double sum = 0;
  for (int dx = -k.radius; dx <= k.radius; ++dx) {
    double lsf = 0;
    for (int dy = -k.radius; dy <= k.radius; ++dy) lsf += k.at(dx, dy);
    sum += lsf * std::cos(2.0 * kPiT * nu * dx * pitch_um);
  }
  return sum;
}

// Encircled energy of a radial PSF table within r: Simpson's rule on the table's own samples up to
// the last even sample below r, the rest (under two samples) by the trapezoid rule.
double encircled(const RadialPsf& p, double r) {
  auto f = [&](double x) { return 2.0 * kPiT * x * p(x); };
  int n = static_cast<int>(r / p.dr_um);
  n -= n % 2;
  double sum = 0;
  for (int k = 0; k < n; k += 2) {
    double a = k * p.dr_um;
    sum += p.dr_um / 3.0 * (f(a) + 4.0 * f(a + p.dr_um) + f(a + 2.0 * p.dr_um));
  }
  double a = n * p.dr_um;
  const int m = 16;
  for (int i = 0; i < m; ++i) {
    double x0 = a + (r - a) * i / m, x1 = a + (r - a) * (i + 1) / m;
    sum += 0.5 * (f(x0) + f(x1)) * (x1 - x0);
  }
  return sum;
}
}  // namespace

TEST(CameraPsf, AiryEncircledEnergyMatchesBesselClosedForm) {
  for (double nm : {450.0, 650.0}) {
    const double N = 2.8, ln = nm * 1e-3 * N;
    RadialPsf p = airy_psf(nm, N, 40);
    // The first dark ring: v = 3.8317 (first zero of J1), r = 1.2197 lambda N, 83.8 % inside.
    double r1 = 3.83170597 / kPiT * ln;
    EXPECT_LT(p(r1), 1e-4 * p(0)) << nm;
    EXPECT_NEAR(encircled(p, 1.22 * ln), 0.838, 1e-3) << nm;
    for (double r_ln : {0.3, 0.7, 1.22, 1.63, 2.23, 5.0, 10.0}) {
      double v = kPiT * r_ln;
      double j0 = std::cyl_bessel_j(0.0, v), j1 = std::cyl_bessel_j(1.0, v);
      EXPECT_NEAR(encircled(p, r_ln * ln), 1.0 - j0 * j0 - j1 * j1, 2e-4) << nm << " nm, r = " << r_ln << " lambda N";
    }
  }
}

TEST(CameraPsf, PixelKernelFourierTransformIsDiffractionMtfTimesPixelSinc) {
  // A fine grid (pitch 0.3 um, well below lambda N) so the sampled kernel's spectrum has no
  // aliasing below 1/pitch - cutoff: its DFT is MTF(nu) sinc(nu p) exactly up to truncation
  // (40 lambda N: about 0.5 % of the light, renormalised into the kernel) and supersampling.
  const double N = 2.8, pitch = 0.3;
  for (double nm : {450.0, 650.0}) {
    double ln = nm * 1e-3 * N, cutoff = 1.0 / ln;
    PsfKernel k = pixel_kernel(airy_psf(nm, N, 40), pitch, 4, 0.25 * ln);
    EXPECT_NEAR(k.raw_sum, 1.0, 0.01) << nm;
    for (double x : {0.05, 0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9}) {
      double nu = x * cutoff;
      double expect = mtf_circular(x) * sinc(nu * pitch);
      EXPECT_NEAR(kernel_transfer(k, pitch, nu), expect, 0.006) << nm << " nm, nu = " << x << " cutoff";
    }
  }
}

TEST(CameraPsf, DefocusKernelIsDiskTimesDiffractionInFrequency) {
  const double N = 2.8, nm = 550, pitch = 0.4, D = 6.0;  // blur circle 6 um
  double ln = nm * 1e-3 * N, cutoff = 1.0 / ln;
  // Disk alone (no diffraction) and disk convolved with the Airy pattern.
  PsfKernel disk = pixel_kernel(defocus_psf(RadialPsf{}, D), pitch, 8, 0.05);
  PsfKernel both = pixel_kernel(defocus_psf(airy_psf(nm, N, 40), D), pitch, 4, 0.25 * ln);
  for (double x : {0.05, 0.1, 0.2, 0.3, 0.5, 0.7}) {
    double nu = x * cutoff;
    EXPECT_NEAR(kernel_transfer(disk, pitch, nu), mtf_disk(D, nu) * sinc(nu * pitch), 0.006) << "disk, x = " << x;
    EXPECT_NEAR(kernel_transfer(both, pitch, nu), mtf_circular(x) * mtf_disk(D, nu) * sinc(nu * pitch), 0.006)
        << "disk x Airy, x = " << x;
  }
}

TEST(CameraPsf, PsfFromDiffractionMtfTableIsTheAiryPattern) {
  // The MTF file path: a radial MTF table sampled from the closed form gives back the Airy PSF.
  const double N = 2.0, nm = 500, ln = nm * 1e-3 * N;
  std::vector<double> f, m;
  for (int i = 0; i <= 400; ++i) {
    double x = i / 400.0;
    f.push_back(x / ln * 1e3);  // cycles per mm
    m.push_back(mtf_circular(x));
  }
  RadialPsf p = psf_from_mtf(f, m, 20 * ln);
  double peak = airy_intensity(0, nm, N);
  for (double r_ln : {0.0, 0.3, 0.6, 1.0, 1.22, 1.7, 2.5})
    EXPECT_NEAR(p(r_ln * ln), airy_intensity(r_ln * ln, nm, N), 5e-3 * peak) << "r = " << r_ln << " lambda N";
}

TEST(CameraPsf, MeasuredPsfImageKernelKeepsCentroidAndVariance) {
  // A sampled elliptical Gaussian, centred 2 um right of the image centre (sigma_x 2 um, sigma_y
  // 1 um, 0.25 um grid), integrated over 1 um pixels: the kernel's centroid is (2, 0) um and its
  // variances sigma^2 + p^2 / 12 (pixel box) + h^2 / 6 (bilinear interpolation of samples h apart).
  PsfImage img;
  img.pitch_um = 0.25;
  img.width = 121;
  img.height = 81;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      double xu = (x - 60) * img.pitch_um - 2.0, yu = (y - 40) * img.pitch_um;
      img.v.push_back(std::exp(-0.5 * (xu * xu / 4.0 + yu * yu / 1.0)));
    }
  const double p = 1.0;
  PsfKernel k = image_kernel(img, p, 4);
  double sum = 0, mx = 0, my = 0;
  for (int dy = -k.radius; dy <= k.radius; ++dy)
    for (int dx = -k.radius; dx <= k.radius; ++dx) {
      sum += k.at(dx, dy);
      mx += k.at(dx, dy) * dx * p;
      my += k.at(dx, dy) * dy * p;
    }
  double vx = 0, vy = 0;
  for (int dy = -k.radius; dy <= k.radius; ++dy)
    for (int dx = -k.radius; dx <= k.radius; ++dx) {
      vx += k.at(dx, dy) * (dx * p - mx) * (dx * p - mx);
      vy += k.at(dx, dy) * (dy * p - my) * (dy * p - my);
    }
  EXPECT_NEAR(sum, 1.0, 1e-5);
  EXPECT_NEAR(mx, 2.0, 0.01);
  EXPECT_NEAR(my, 0.0, 0.01);
  double h2 = img.pitch_um * img.pitch_um;
  EXPECT_NEAR(vx, 4.0 + p * p / 12 + h2 / 6, 0.01 * 4);
  EXPECT_NEAR(vy, 1.0 + p * p / 12 + h2 / 6, 0.01 * 1);
  // A defocus disk convolved in: variance adds D^2 / 16 (uniform disk of diameter D, per axis).
  const double D = 6.0;
  PsfKernel both = convolve_kernels(k, pixel_kernel(defocus_psf(RadialPsf{}, D), p, 8, D / 16));
  double vx2 = 0, m2 = 0;
  for (int dy = -both.radius; dy <= both.radius; ++dy)
    for (int dx = -both.radius; dx <= both.radius; ++dx) m2 += both.at(dx, dy) * dx * p;
  for (int dy = -both.radius; dy <= both.radius; ++dy)
    for (int dx = -both.radius; dx <= both.radius; ++dx) vx2 += both.at(dx, dy) * (dx * p - m2) * (dx * p - m2);
  // The disk kernel is pixel-integrated too: + p^2 / 12 once more.
  EXPECT_NEAR(vx2, vx + D * D / 16 + p * p / 12, 0.02 * vx2);
}
