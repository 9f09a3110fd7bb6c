// Lens optics between scene radiance and sensor irradiance, and the per-pixel geometry that the
// angle-dependent parts (cos^4 fall-off, interference-filter shift) need.
//   E(lambda) = pi T(lambda) L(lambda) / (1 + 4 N^2 (1 - m)^2) * cos^4(theta)
// (the camera equation of ISETCam / EMVA 1288 with the working f-number N (1 - m), m <= 0), where
// theta is the field angle of the pixel's chief ray. The sensor pixel grid is the EXR's pixel grid
// (one radiance pixel per sensor pixel); the optical axis meets the image centre.
//
// Field angles come, in this order of preference, from the lens focal length and pixel pitch
// (tan theta = r / (f (1 - m)), r the pixel's distance from the image centre), or from the
// render camera's vertical field of view in the EXR header (oralfluor.vfov_deg), or are zero
// (with a warning when the camera has interference filters or cos^4 on).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/camera/description/camera_description.h"
#include "renderer/image/spectral_image.h"

namespace ofl {

struct FieldGeometry {
  enum class Source { kLens, kRenderFov, kNone };
  Source source = Source::kNone;
  int width = 0, height = 0;
  double pixels_per_tan = 0;   // image distance in pixel units: tan(theta) = r_px / pixels_per_tan
  double sensor_tan_per_px = -1;  // tan(sensor CRA) per pixel of image height; < 0: equal to the field angle
  double axis_x_px = 0, axis_y_px = 0;  // optical axis relative to the image centre (optics "sensor_offset_um")

  // Distance of the centre of pixel (x, y) from the optical axis, in pixels.
  double radius_px(int x, int y) const;
  double max_radius_px() const;  // at the farthest corner pixel's centre
  double field_angle(double r_px) const;   // radians, object side
  double sensor_angle(double r_px) const;  // radians, image side at the sensor
  // The vertical field of view this geometry implies (degrees), 0 when unknown.
  double vfov_deg() const;
  const char* source_name() const;
  nlohmann::json to_json() const;
};

// `render_vfov_deg` is the EXR's oralfluor.vfov_deg when present. Warnings (inconsistent render and
// camera geometry, angle-dependent parts evaluated on axis) are appended to `warnings`.
FieldGeometry make_field_geometry(const LensDescription& lens, const SensorDescription& sensor, int width, int height,
                                  std::optional<double> render_vfov_deg, std::vector<std::string>* warnings);

// The EXR's oralfluor.vfov_deg, when present and a number (an angle in (0, 180); otherwise a warning
// and nothing).
std::optional<double> render_vfov_deg(const SpectralImage& radiance, std::vector<std::string>* warnings);

// pi / (1 + 4 N^2 (1 - m)^2): sensor irradiance per unit scene radiance on axis (sr), T excluded.
double irradiance_factor(const LensDescription& lens);
// cos^4(theta) when the lens has "cos4", else 1.
double relative_illumination(const LensDescription& lens, double field_angle_rad);

}  // namespace ofl
