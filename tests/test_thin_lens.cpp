// Thin-lens camera: an edge off the focus plane is blurred by the circle of confusion of an ideal
// thin lens, diameter 2 a |1/z - 1/z_focus| in units of the image-plane tangent; in focus it stays
// sharp.
#include <gtest/gtest.h>

#include <cmath>

#include "renderer/core/files/json_node.h"
#include "renderer/render/render_job.h"
#include "renderer/spectral/spectra/units.h"

using namespace ofl;

namespace {
// Renders a black/white edge (x < 0 white) at distance z from a camera focused at z_focus, and
// returns the row-averaged profile across the edge.
std::vector<double> edge_profile(double z, double z_focus, double f_number, int width) {
  nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                      {"integrator", {{"spp", 256}, {"max_depth", 0}, {"wavelengths", {{"min_nm", 500}, {"max_nm", 600}, {"step_nm", 10}}},
                                      {"output_bands", {{"min_nm", 520}, {"max_nm", 580}, {"step_nm", 20}}}}},
                      {"camera", {{"type", "thin_lens"}, {"position", {0, 0, z}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}},
                                  {"focal_length_mm", 8}, {"sensor_height_mm", 2}, {"f_number", f_number}, {"focus_distance_m", z_focus},
                                  {"resolution", {width, width / 4}}}},
                      {"materials", {{"white", {{"type", "lambertian"}, {"emission", 1.0}}}}},
                      {"geometry", {{{"type", "quad"}, {"center", {-0.5, 0, 0}}, {"u", {1, 0, 0}}, {"v", {0, 1, 0}}, {"material", "white"}}}}};
  Scene sc = load_scene(JsonFile::from(j, "thin_lens.json"));
  RenderResult r = render(sc);
  std::vector<double> prof(width, 0.0);
  for (int y = 0; y < r.image.height; ++y)
    for (int x = 0; x < width; ++x) prof[x] += r.image.pixel(x, y)[1] / r.image.height;
  return prof;
}

// Width in pixels between the 10 % and 90 % crossings of a falling edge profile.
double width_10_90(const std::vector<double>& p) {
  double hi = p.front(), lo = p.back();
  auto cross = [&](double level) {
    double v = lo + level * (hi - lo);
    for (size_t i = 1; i < p.size(); ++i)
      if (p[i - 1] >= v && p[i] < v) return i - 1 + (p[i - 1] - v) / (p[i - 1] - p[i]);
    return -1.0;
  };
  return cross(0.1) - cross(0.9);
}
}  // namespace

TEST(ThinLens, DefocusBlurMatchesTheCircleOfConfusion) {
  const int W = 128;
  const double z = 0.05, zf = 0.10, N = 1.0;
  const double a = 0.5 * 8e-3 / N;  // aperture radius
  // Pixels per unit tangent: (W / 2) / tan(hfov / 2), with tan(vfov / 2) = 1 mm / 8 mm, W/4 rows.
  double tan_h = (1.0 / 8.0) * 4.0;
  double px_per_tan = (W / 2.0) / tan_h;
  double R = a * std::fabs(1 / z - 1 / zf) * px_per_tan;  // blur radius in pixels
  // 10-90 % width of an edge blurred by a uniform disk of radius R: the chord-area function
  // E(x) = 1/2 - (x sqrt(R^2 - x^2) + R^2 asin(x / R)) / (pi R^2) crosses 0.9 and 0.1 at +-x*.
  double lo = 0, hi = R;
  for (int it = 0; it < 60; ++it) {
    double x = 0.5 * (lo + hi);
    double e = 0.5 - (x * std::sqrt(R * R - x * x) + R * R * std::asin(x / R)) / (kPi * R * R);
    (e > 0.1 ? lo : hi) = x;
  }
  double expected = 2 * lo;
  double measured = width_10_90(edge_profile(z, zf, N, W));
  EXPECT_NEAR(measured, expected, 0.08 * expected + 0.5) << "blur radius " << R << " px";
  // In focus the edge is only as wide as the pixel box filter allows (about 0.8 px).
  EXPECT_LT(width_10_90(edge_profile(zf, zf, N, W)), 1.2);
}
