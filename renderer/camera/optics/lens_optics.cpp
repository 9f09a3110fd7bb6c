#include "renderer/camera/optics/lens_optics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "renderer/spectral/spectra/units.h"

namespace ofl {

std::optional<double> render_vfov_deg(const SpectralImage& img, std::vector<std::string>* warnings) {
  auto it = img.attributes.find("oralfluor.vfov_deg");
  if (it == img.attributes.end()) return std::nullopt;
  char* end = nullptr;
  double v = std::strtod(it->second.c_str(), &end);
  if (end == it->second.c_str() || !(v > 0 && v < 180)) {
    if (warnings) warnings->push_back("ignoring oralfluor.vfov_deg \"" + it->second + "\" (not an angle in (0, 180))");
    return std::nullopt;
  }
  return v;
}

double FieldGeometry::radius_px(int x, int y) const {
  double dx = x + 0.5 - 0.5 * width - axis_x_px, dy = y + 0.5 - 0.5 * height - axis_y_px;
  return std::sqrt(dx * dx + dy * dy);
}

double FieldGeometry::max_radius_px() const {
  return std::max(std::max(radius_px(0, 0), radius_px(width - 1, 0)),
                  std::max(radius_px(0, height - 1), radius_px(width - 1, height - 1)));
}

double FieldGeometry::field_angle(double r) const {
  return pixels_per_tan > 0 ? std::atan(r / pixels_per_tan) : 0.0;
}

double FieldGeometry::sensor_angle(double r) const {
  return sensor_tan_per_px >= 0 ? std::atan(r * sensor_tan_per_px) : field_angle(r);
}

double FieldGeometry::vfov_deg() const {
  return pixels_per_tan > 0 ? 2.0 * std::atan(0.5 * height / pixels_per_tan) * 180.0 / kPi : 0.0;
}

const char* FieldGeometry::source_name() const {
  switch (source) {
    case Source::kLens: return "lens focal length and pixel pitch";
    case Source::kRenderFov: return "EXR oralfluor.vfov_deg";
    case Source::kNone: return "none (on-axis everywhere)";
  }
  return "";
}

nlohmann::json FieldGeometry::to_json() const {
  const char* src = source == Source::kLens ? "lens" : source == Source::kRenderFov ? "render_vfov" : "none";
  nlohmann::json j = {{"source", src}, {"width", width}, {"height", height}, {"pixels_per_tan", pixels_per_tan},
                      {"vfov_deg", vfov_deg()}, {"max_field_angle_deg", field_angle(max_radius_px()) * 180.0 / kPi}};
  if (sensor_tan_per_px >= 0) j["sensor_tan_per_px"] = sensor_tan_per_px;
  if (axis_x_px != 0 || axis_y_px != 0) j["axis_offset_px"] = {axis_x_px, axis_y_px};
  return j;
}

FieldGeometry make_field_geometry(const LensDescription& lens, const SensorDescription& sensor, int width, int height,
                                  std::optional<double> render_vfov, std::vector<std::string>* warnings) {
  FieldGeometry g;
  g.width = width;
  g.height = height;
  if (lens.focal_length_mm > 0) {
    g.source = FieldGeometry::Source::kLens;
    double image_distance_mm = lens.focal_length_mm * (1.0 - lens.magnification);
    g.pixels_per_tan = image_distance_mm * 1000.0 / sensor.pixel_pitch_um;
    if (render_vfov && *render_vfov > 0 && warnings) {
      double rel = std::fabs(g.vfov_deg() / *render_vfov - 1.0);
      if (rel > 0.02) {
        std::ostringstream w;
        w << "the camera's lens and pixel pitch give a vertical field of view of " << g.vfov_deg()
          << " deg but the image was rendered with " << *render_vfov
          << " deg; field angles follow the camera (check focal_length_mm and pixel_pitch_um)";
        warnings->push_back(w.str());
      }
    }
  } else if (render_vfov && *render_vfov > 0 && *render_vfov < 180) {
    g.source = FieldGeometry::Source::kRenderFov;
    g.pixels_per_tan = 0.5 * height / std::tan(0.5 * *render_vfov * kPi / 180.0);
  } else {
    g.source = FieldGeometry::Source::kNone;
    if (warnings && (lens.cos4 || lens.sensor_cra_deg >= 0))
      warnings->push_back(
          "no lens focal_length_mm and no oralfluor.vfov_deg in the EXR: field angles are taken as zero "
          "(no cos^4 fall-off, no interference-filter shift)");
  }
  if (lens.sensor_cra_deg >= 0) {
    double rmax = g.max_radius_px();
    g.sensor_tan_per_px = rmax > 0 ? std::tan(lens.sensor_cra_deg * kPi / 180.0) / rmax : 0.0;
  }
  return g;
}

double irradiance_factor(const LensDescription& lens) {
  double nw = lens.f_number * (1.0 - lens.magnification);
  return kPi / (1.0 + 4.0 * nw * nw);
}

double relative_illumination(const LensDescription& lens, double theta) {
  if (!lens.cos4) return 1.0;
  double c = std::cos(theta);
  return c * c * c * c;
}

}  // namespace ofl
