#include "renderer/interop/iset_oi.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "renderer/camera/camera_pipeline.h"
#include "renderer/camera/optics/lens_optics.h"
#include "renderer/camera/optics/optics.h"
#include "renderer/camera/sensor/expected_signal.h"
#include "renderer/core/errors/error.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {
namespace {

constexpr int kSamplesPerBand = 16;  // midpoint rule over each band for <T lambda / (h c)>
constexpr int kRadiusSamples = 65;   // field radii at which angle-dependent filters are tabulated

// <T(lambda) lambda / (h c)>_b per band at radius `r_px` (T: lens times filter stack).
std::vector<double> band_photon_transmission(const CameraDescription& cam, const FieldGeometry& g, double r_px,
                                             const std::vector<double>& lo, const std::vector<double>& hi) {
  const double af = g.field_angle(r_px), as = g.sensor_angle(r_px);
  std::vector<double> out(lo.size());
  for (size_t b = 0; b < lo.size(); ++b) {
    double sum = 0;
    for (int k = 0; k < kSamplesPerBand; ++k) {
      double nm = lo[b] + (hi[b] - lo[b]) * (k + 0.5) / kSamplesPerBand;
      sum += cam.lens.transmittance(nm) * cam.filters.transmittance(nm, af, as) * photons_per_joule(nm);
    }
    out[b] = sum / kSamplesPerBand;
  }
  return out;
}

// Column-major rows x cols x bands irradiance photons (see the header), and their sum.
MatValue irradiance_photons(const SpectralImage& L, const CameraDescription& cam, const FieldGeometry& g, double* sum) {
  const size_t H = L.height, W = L.width, B = L.bands();
  auto lo = L.band_lo(), hi = L.band_hi();
  const bool varies = cam.filters.any_interference() && (g.pixels_per_tan > 0 || g.sensor_tan_per_px > 0);
  const int n = varies ? kRadiusSamples : 1;
  const double rmax = g.max_radius_px();
  std::vector<std::vector<double>> table;
  for (int k = 0; k < n; ++k) table.push_back(band_photon_transmission(cam, g, n == 1 ? 0.0 : rmax * k / (n - 1), lo, hi));
  const double k0 = irradiance_factor(cam.lens);
  std::vector<double> out(H * W * B);
  double s = 0;
  for (size_t y = 0; y < H; ++y)
    for (size_t x = 0; x < W; ++x) {
      const double r = g.radius_px(int(x), int(y));
      const double t = n == 1 || rmax <= 0 ? 0.0 : std::min(double(n - 1), r / rmax * (n - 1));
      const int i0 = int(t), i1 = std::min(i0 + 1, n - 1);
      const double f = t - i0, ri = relative_illumination(cam.lens, g.field_angle(r));
      const float* p = L.pixel(int(x), int(y));
      for (size_t b = 0; b < B; ++b) {
        double tr = (1 - f) * table[i0][b] + f * table[i1][b];
        float q = float(k0 * ri * p[b] * tr);
        out[b * H * W + x * H + y] = q;
        s += q;
      }
    }
  *sum = s;
  return MatValue::array({H, W, B}, std::move(out), true);
}

}  // namespace

IsetOi make_iset_oi(const SpectralImage& radiance_in, const CameraDescription& cam, const std::string& source) {
  if (radiance_in.width <= 0 || radiance_in.height <= 0 || radiance_in.bands() == 0) throw InputError(source, "", "empty spectral image");
  IsetOi r;
  SpectralImage radiance = radiance_in;
  check_radiance(radiance, source, &r.warnings);
  OpticalImage optical;
  if (cam.optics.enabled) {
    optical = form_optical_image(radiance, cam, source);
    r.warnings.insert(r.warnings.end(), optical.warnings.begin(), optical.warnings.end());
  }
  const SpectralImage& L = cam.optics.enabled ? optical.image : radiance;
  FieldGeometry g = sensor_field_geometry(L, cam, optical.axis_x_px, optical.axis_y_px, &r.warnings);
  r.rows = L.height;
  r.cols = L.width;
  r.pixel_pitch_m = cam.sensor.pixel_pitch_um * 1e-6;
  if (cam.lens.focal_length_mm > 0) r.focal_length_m = cam.lens.focal_length_mm * 1e-3;
  else if (g.pixels_per_tan > 0) r.focal_length_m = g.pixels_per_tan * r.pixel_pitch_m;
  else
    throw InputError(source, "oralfluor.vfov_deg",
                     "the sensor's geometry is unknown: the camera's lens has no focal_length_mm and the EXR records no field of view");
  r.hfov_deg = 2.0 * std::atan(0.5 * r.cols * r.pixel_pitch_m / r.focal_length_m) * 180.0 / kPi;

  MatValue& oi = r.oi = MatValue::structure();
  oi.set("type", MatValue::string("opticalimage"));
  oi.set("name", MatValue::string(std::filesystem::path(source).stem().string() + " through " + cam.name));
  MatValue spec = MatValue::structure();
  spec.set("wave", MatValue::vector(L.band_nm, true));
  oi.set("spectrum", spec);
  MatValue data = MatValue::structure();
  data.set("photons", irradiance_photons(L, cam, g, &r.photon_sum));
  data.set("bitDepth", MatValue::scalar(32));
  oi.set("data", data);
  oi.set("wAngular", MatValue::scalar(r.hfov_deg));
  MatValue optics = MatValue::structure();
  optics.set("type", MatValue::string("optics"));
  optics.set("name", MatValue::string(cam.name + " lens (applied by oralfluor)"));
  optics.set("model", MatValue::string("skip"));
  optics.set("fNumber", MatValue::scalar(cam.lens.f_number));
  optics.set("focalLength", MatValue::scalar(r.focal_length_m));
  oi.set("optics", optics);
  MatValue meta = MatValue::structure();
  meta.set("source", MatValue::string(source));
  meta.set("camera", MatValue::string(cam.name));
  meta.set("units", MatValue::string("data.photons: sensor-plane irradiance, photons s^-1 m^-2 nm^-1 (lens, filters, cos^4 applied)"));
  meta.set("pixelPitchM", MatValue::scalar(r.pixel_pitch_m));
  meta.set("geometry", MatValue::string(g.to_json().dump()));
  if (cam.optics.enabled) meta.set("opticsStage", MatValue::string(optical.info.dump()));
  oi.set("metadata", meta);
  return r;
}

void write_iset_oi(const std::filesystem::path& file, const IsetOi& oi) { write_mat_file(file, {{"oi", oi.oi}}); }

}  // namespace ofl
