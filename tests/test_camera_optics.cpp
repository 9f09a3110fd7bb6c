// Camera optics: the camera equation's irradiance factor, cos^4 fall-off, field angles from the
// lens or from the render's field of view, and the angle shift of interference filters per pixel.
#include <gtest/gtest.h>

#include <cmath>

#include "camera_test_util.h"
#include "renderer/camera/camera_pipeline.h"

using namespace ofl;
using namespace ofl::testing;

namespace {
constexpr double kPiT = 3.14159265358979323846;

// The 50 % point of a filter stack at the given angles, by bisection.
double half_point(const FilterStack& st, double aoi_front, double aoi_sensor, double lo, double hi) {
  double target = 0.5 * (st.transmittance(hi, aoi_front, aoi_sensor) + st.transmittance(lo, aoi_front, aoi_sensor));
  for (int i = 0; i < 200; ++i) {
    double mid = 0.5 * (lo + hi);
    (st.transmittance(mid, aoi_front, aoi_sensor) < target) ? lo = mid : hi = mid;
  }
  return 0.5 * (lo + hi);
}

OpticalFilter longpass(double edge, double width, double n_eff) {
  OpticalFilter f;
  f.kind = OpticalFilter::Kind::kLongpass;
  f.edge_nm = edge;
  f.width_nm = width;
  f.od = 4;
  f.peak = 0.9;
  f.interference = true;
  f.n_eff = n_eff;
  return f;
}
}  // namespace

TEST(CameraOptics, IrradianceFactorIsTheCameraEquation) {
  LensDescription l;
  l.f_number = 2.0;
  l.magnification = -0.5;
  // pi / (1 + 4 N^2 (1 - m)^2) = pi / (1 + 4 * 4 * 2.25) = pi / 37
  EXPECT_NEAR(irradiance_factor(l), kPiT / 37.0, 1e-15);
  l.magnification = 0;
  EXPECT_NEAR(irradiance_factor(l), kPiT / 17.0, 1e-15);
}

TEST(CameraOptics, FieldAnglesFromRenderFieldOfView) {
  LensDescription lens;  // no focal length: the EXR's vfov decides
  SensorDescription s;
  std::vector<std::string> warnings;
  FieldGeometry g = make_field_geometry(lens, s, 64, 48, 40.0, &warnings);
  EXPECT_EQ(g.source, FieldGeometry::Source::kRenderFov);
  double r = std::hypot(31.5, 23.5);
  EXPECT_NEAR(g.field_angle(g.radius_px(0, 0)), std::atan(r / 24.0 * std::tan(20.0 * kPiT / 180)), 1e-12);
  EXPECT_NEAR(g.vfov_deg(), 40.0, 1e-9);
  EXPECT_TRUE(warnings.empty());
  // A lens that disagrees with the render by more than 2 % is used, with a warning.
  lens.focal_length_mm = 1.0;
  s.pixel_pitch_um = 3.0;
  FieldGeometry gl = make_field_geometry(lens, s, 64, 48, 40.0, &warnings);
  EXPECT_EQ(gl.source, FieldGeometry::Source::kLens);
  EXPECT_NEAR(gl.field_angle(gl.radius_px(0, 0)), std::atan(r * 3e-3 / 1.0), 1e-12);
  EXPECT_EQ(warnings.size(), 1u);
}

TEST(CameraOptics, Cos4FallOffAcrossTheImage) {
  CameraDescription cam = box_camera();
  cam.lens.cos4 = true;
  cam.lens.focal_length_mm = 0.2;
  cam.lens.magnification = -0.2;
  SpectralImage img = uniform_image(80, 60, bands(400, 700, 10), 0.05);
  CameraRunOptions o;
  o.noise = false;
  CameraRun r = simulate_camera(img, cam, o, "uniform");
  auto angle = [&](int x, int y) {
    double rx = (x + 0.5 - 40) * 3e-3, ry = (y + 0.5 - 30) * 3e-3;  // mm
    return std::atan(std::hypot(rx, ry) / (0.2 * 1.2));            // image distance f (1 - m)
  };
  auto e = [&](int x, int y) { return r.expected.channel_e[(static_cast<size_t>(y) * 80 + x) * 3 + kGreen]; };
  double c4c = std::pow(std::cos(angle(0, 0)), 4), c4m = std::pow(std::cos(angle(40, 30)), 4);
  EXPECT_LT(c4c, 0.6);  // a wide angle, so the check means something
  EXPECT_NEAR(e(0, 0) / e(40, 30), c4c / c4m, 1e-5);
  EXPECT_NEAR(e(79, 59) / e(40, 30), c4c / c4m, 1e-5);
}

TEST(CameraOptics, ShiftedFilterEdgeAtCornerPixelFollowsTheFormula) {
  CameraDescription cam = box_camera();
  cam.lens.focal_length_mm = 0.5;
  cam.sensor.qe = {constant_spectrum(0.0), box(380, 720, 1.0), constant_spectrum(0.0)};
  cam.filters.filters.push_back({longpass(550, 10, 1.8), FilterPosition::kFrontOfLens});
  const int W = 200, H = 150;
  SpectralImage img = uniform_image(W, H, bands(400, 700, 10), 0.05);
  CameraRunOptions o;
  o.noise = false;
  CameraRun r = simulate_camera(img, cam, o, "uniform");

  // Independent expectation for the corner pixel: field angle from the geometry, edge from
  // lambda(theta) = lambda0 sqrt(1 - (sin theta / n_eff)^2).
  double theta = std::atan(std::hypot(W / 2 - 0.5, H / 2 - 0.5) * 3e-3 / 0.5);
  double edge = 550 * std::sqrt(1 - std::pow(std::sin(theta) / 1.8, 2));
  EXPECT_GT(theta * 180 / kPiT, 35.0);
  EXPECT_NEAR(r.geometry.field_angle(r.geometry.radius_px(0, 0)), theta, 1e-12);
  EXPECT_NEAR(half_point(cam.filters, theta, 0, 450, 650), edge, 1e-6);
  EXPECT_LT(edge, 550 - 25);  // the shift is tens of nm

  // Electrons of the corner pixel: the logistic edge (10-90 % in width w: scale w / (2 ln 9)) over
  // the bands, integrated at 0.01 nm.
  const double h = 6.62607015e-34, c = 299792458.0;
  double s = 10.0 / (2 * std::log(9.0)), tmin = 1e-4;
  double integral = 0;
  for (double nm = 395.005; nm < 705; nm += 0.01) {
    double T = tmin + (0.9 - tmin) / (1 + std::exp(-(nm - edge) / s));
    integral += T * nm * 0.01;
  }
  double scale = 0.01 * 9e-12 * irradiance_factor(cam.lens) * 0.05 * 1e-9 / (h * c);
  for (auto [x, y] : {std::pair{0, 0}, std::pair{W - 1, 0}, std::pair{0, H - 1}, std::pair{W - 1, H - 1}}) {
    double e = r.expected.channel_e[(static_cast<size_t>(y) * W + x) * 3 + kGreen];
    EXPECT_NEAR(e / (scale * integral), 1.0, 2e-4) << x << "," << y;
  }
  // The centre sees the filter almost at normal incidence: its edge is redder, so it passes less.
  double centre = r.expected.channel_e[(static_cast<size_t>(H / 2) * W + W / 2) * 3 + kGreen];
  EXPECT_LT(centre, r.expected.channel_e[kGreen]);
}

TEST(CameraOptics, SensorSideFilterUsesTheLensChiefRayAngle) {
  LensDescription lens;
  lens.focal_length_mm = 0.5;
  lens.sensor_cra_deg = 25;
  SensorDescription s;
  s.pixel_pitch_um = 3;
  FieldGeometry g = make_field_geometry(lens, s, 200, 150, std::nullopt, nullptr);
  double rc = g.radius_px(0, 0);
  EXPECT_NEAR(g.sensor_angle(rc), 25 * kPiT / 180, 1e-12);
  EXPECT_NEAR(std::tan(g.sensor_angle(0.5 * rc)), 0.5 * std::tan(25 * kPiT / 180), 1e-12);
  FilterStack st;
  st.filters.push_back({longpass(700, 15, 1.8), FilterPosition::kAtSensor});
  double expect = 700 * std::sqrt(1 - std::pow(std::sin(25 * kPiT / 180) / 1.8, 2));
  // Sensor-side filters ignore the object-side angle and follow the CRA.
  EXPECT_NEAR(half_point(st, g.field_angle(rc), g.sensor_angle(rc), 600, 800), expect, 1e-6);
}
