// A slanted-edge MTF (ISO 12233 style) measured on a rendered edge through the optical-image
// stage agrees with the closed form: diffraction MTF of the f-number x the sensor pixel's
// aperture (sinc), times the known small factors of the measurement chain (the defocus of the
// edge at 0.3 m with the lens at infinity, the render's own pixel
// box and the render grid's two piecewise-constant holds, the ESF bins and the finite difference;
// together 0.81 at the sensor's Nyquist frequency). Tolerance 0.02 (render noise at 16 spp, the ESF window of +-14 pixels; measured 0.014 at most).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <nlohmann/json.hpp>

#include "camera_test_util.h"
#include "renderer/camera/description/camera_description.h"
#include "renderer/camera/optics/optics.h"
#include "renderer/core/files/json_node.h"
#include "renderer/render/render_job.h"
#include "renderer/scene/scene.h"

using namespace ofl;
using nlohmann::json;

namespace {
constexpr double kPiT = 3.14159265358979323846;
constexpr int kRender = 128, kSensor = 32;  // a render pixel is 1/4 of a sensor pixel
constexpr double kFov = 4.0, kPitch = 3.0, kN = 8.0, kSlantDeg = 5.0;

double mtf_circular(double x) { return x >= 1 ? 0 : 2.0 / kPiT * (std::acos(x) - x * std::sqrt(1 - x * x)); }
double sinc(double x) { return std::fabs(x) < 1e-12 ? 1.0 : std::sin(kPiT * x) / (kPiT * x); }
double disk_mtf(double d_um, double nu_per_um) {
  double a = kPiT * d_um * nu_per_um;
  return a < 1e-12 ? 1.0 : 2.0 * std::cyl_bessel_j(1.0, a) / a;
}

// A white Lambertian quad whose left edge runs through the view centre, tilted 5 degrees from the
// image vertical; nothing behind it (black). A point LED beside the camera, green light only.
json edge_scene() {
  double c = std::cos(kSlantDeg * kPiT / 180.0), s = std::sin(kSlantDeg * kPiT / 180.0);
  double h = 0.05;  // half size of the quad (m); the view is 2 cm wide at 0.3 m
  // Quad with edge vectors u (across the edge) and v (along it), normal +z; its left edge
  // (centre - u / 2) passes through the origin.
  json u = {2 * h * c, -2 * h * s, 0}, v = {2 * h * s, 2 * h * c, 0};
  json center = {h * c, -h * s, 0};
  return {{"format", "oralfluor-scene"},
          {"version", 1},
          {"integrator", {{"spp", 16}, {"seed", 5}, {"max_depth", 1},
                          {"wavelengths", {{"min_nm", 530}, {"max_nm", 570}, {"step_nm", 10}}}}},
          {"camera", {{"position", {0, 0, 0.3}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", kFov},
                      {"resolution", {kRender, kRender}}}},
          {"materials", {{"white", {{"type", "lambertian"}, {"reflectance", 0.9}}}}},
          {"geometry", {{{"type", "quad"}, {"center", center}, {"u", u}, {"v", v}, {"material", "white"}}}},
          {"lights", {{{"type", "led"}, {"spd", {{"type", "gaussian"}, {"peak_nm", 550}, {"fwhm_nm", 30}}},
                       {"radiant_intensity_W_sr", 1.0}, {"profile", {{"cos_power", 0}}}, {"position", {0.01, 0, 0.3}},
                       {"axis", {0, 0, -1}}}}}};
}

// Edge position (x where the row crosses half the white level) in every row, fitted by a line.
void fit_edge(const std::vector<double>& img, int n, double white, double* x_at0, double* slope) {
  std::vector<double> ys, xs;
  for (int y = 2; y < n - 2; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      double a = img[y * n + x], b = img[y * n + x + 1];
      if ((a - 0.5 * white) * (b - 0.5 * white) <= 0 && a != b) {
        xs.push_back(x + 0.5 + (0.5 * white - a) / (b - a));
        ys.push_back(y + 0.5);
        break;
      }
    }
  double my = 0, mx = 0, sxy = 0, syy = 0;
  for (size_t i = 0; i < xs.size(); ++i) my += ys[i] / xs.size(), mx += xs[i] / xs.size();
  for (size_t i = 0; i < xs.size(); ++i) sxy += (ys[i] - my) * (xs[i] - mx), syy += (ys[i] - my) * (ys[i] - my);
  *slope = sxy / syy;
  *x_at0 = mx - *slope * my;
}
}  // namespace

TEST(CameraSlantedEdge, RenderedEdgeMtfIsDiffractionTimesPixelAperture) {
  RenderOptions ro;
  ro.progress = false;
  RenderResult r = render(load_scene(JsonFile::from(edge_scene(), "edge")), ro);
  SpectralImage& img = r.image;
  ASSERT_EQ(img.width, kRender);

  // Camera: f chosen so a render pixel is a quarter of a 3 um sensor pixel; f/8 puts the
  // diffraction cutoff (1 / (lambda N) = 227 cycles/mm at 550 nm) near the sensor's Nyquist (167).
  CameraDescription cam = ofl::testing::box_camera();
  cam.sensor.pixel_pitch_um = kPitch;
  cam.lens.f_number = kN;
  cam.lens.focal_length_mm = 0.25 * kPitch * kRender / (1000.0 * 2.0 * std::tan(0.5 * kFov * kPiT / 180.0));
  cam.optics.enabled = true;
  cam.optics.sensor_width_px = cam.optics.sensor_height_px = kSensor;
  cam.optics.psf_extent_lambda_n = 30;
  OpticalImage oi = form_optical_image(img, cam, "edge.exr");
  ASSERT_NEAR(oi.info["render_pixels_per_sensor_pixel"].get<double>(), 4.0, 1e-9);
  int b550 = 0;
  for (int b = 0; b < oi.image.bands(); ++b)
    if (std::fabs(oi.image.band_nm[b] - 550) < 1e-6) b550 = b;
  std::vector<double> s(kSensor * kSensor);
  for (int y = 0; y < kSensor; ++y)
    for (int x = 0; x < kSensor; ++x) s[y * kSensor + x] = oi.image.pixel(x, y)[b550];
  double white = 0;
  for (int y = 0; y < kSensor; ++y) white += s[y * kSensor + kSensor - 3] / kSensor;
  ASSERT_GT(white, 0);

  // ESF: every pixel's signed distance from the fitted edge (along the row, times cos of the
  // slant), binned at 1/4 pixel; LSF by central differences; MTF by a direct DFT.
  double x0, slope;
  fit_edge(s, kSensor, white, &x0, &slope);
  EXPECT_NEAR(std::atan(std::fabs(slope)) * 180.0 / kPiT, kSlantDeg, 0.5);
  const double bin = 0.25, half = 14.0;
  const int nb = static_cast<int>(2 * half / bin);
  std::vector<double> sum(nb, 0), cnt(nb, 0);
  double cosang = 1.0 / std::sqrt(1.0 + slope * slope);
  for (int y = 0; y < kSensor; ++y)
    for (int x = 0; x < kSensor; ++x) {
      double d = (x + 0.5 - (x0 + slope * (y + 0.5))) * cosang;
      int k = static_cast<int>(std::floor((d + half) / bin));
      if (k < 0 || k >= nb) continue;
      sum[k] += s[y * kSensor + x] / white;
      ++cnt[k];
    }
  std::vector<double> esf(nb);
  for (int k = 0; k < nb; ++k) {
    ASSERT_GT(cnt[k], 0) << "empty ESF bin " << k;
    esf[k] = sum[k] / cnt[k];
  }
  std::vector<double> lsf(nb, 0.0);
  for (int k = 1; k + 1 < nb; ++k) lsf[k] = 0.5 * (esf[k + 1] - esf[k - 1]);
  auto transfer = [&](double nu) {  // nu in cycles per sensor pixel
    double re = 0, im = 0;
    for (int k = 0; k < nb; ++k) {
      double d = (k + 0.5) * bin - half;
      re += lsf[k] * std::cos(2 * kPiT * nu * d);
      im += lsf[k] * std::sin(2 * kPiT * nu * d);
    }
    return std::hypot(re, im);
  };
  double dc = transfer(0);
  const double ln_px = 0.550 * kN / kPitch;  // lambda N in sensor pixels
  const double f_mm = cam.lens.focal_length_mm, blur_um = (f_mm / kN) * f_mm / 300.0 * 1000.0;
  for (double nu : {0.05, 0.1, 0.2, 0.3, 0.4, 0.5}) {
    double measured = transfer(nu) / dc;
    double theory = mtf_circular(nu * ln_px) * sinc(nu);              // diffraction x pixel aperture
    // The render pixel's own box, and the two piecewise-constant holds of the render grid (PSF
    // convolution of the held render, resampling of the held optical image): each a box of 1/4 pixel.
    double chain = std::pow(sinc(0.25 * nu), 3) * sinc(bin * nu) * sinc(2 * bin * nu);  // + ESF bins, central difference
    // The lens is focused at infinity and the edge is 0.3 m away: a blur circle of A f / d = 0.79 um
    // (the stage reads the render's aov.depth) multiplies the MTF by 2 J1(pi c nu) / (pi c nu), 0.98 at Nyquist.
    chain *= disk_mtf(blur_um, nu / kPitch);
    EXPECT_NEAR(measured, theory * chain, 0.02) << "nu = " << nu << " cycles/pixel; theory " << theory;
    // The edge resolves diffraction: without it (pixel aperture and chain only) the MTF would be far higher.
    if (nu >= 0.3) EXPECT_GT(sinc(nu) * chain - measured, 0.1) << "nu = " << nu;
    std::printf("slanted edge: nu %.2f cycles/pixel: measured %.4f, diffraction x sinc x chain %.4f, without diffraction %.4f\n",
                nu, measured, theory * chain, sinc(nu) * chain);
  }
}
