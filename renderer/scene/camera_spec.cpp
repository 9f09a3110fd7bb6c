#include "renderer/scene/camera_spec.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "renderer/spectral/spectra/units.h"

namespace ofl {

CameraSpec parse_camera_spec(const JsonNode& n) {
  n.check_keys({"type", "position", "look_at", "up", "fov_deg", "focal_length_mm", "sensor_height_mm", "f_number",
                "focus_distance_m", "resolution"});
  CameraSpec c;
  std::string type = n.choice_or("type", "pinhole", {"pinhole", "thin_lens"});
  c.model = type == "thin_lens" ? CameraSpec::Model::kThinLens : CameraSpec::Model::kPinhole;
  c.position = n.at("position").vec3();
  c.look_at = n.at("look_at").vec3();
  c.up = n.find("up") ? n.at("up").unit_vec3() : glm::dvec3(0, 0, 1);
  if (glm::length(c.look_at - c.position) < 1e-12) n.at("look_at").fail("look_at equals position");
  if (glm::length(glm::cross(glm::normalize(c.look_at - c.position), c.up)) < 1e-6)
    n.at("up").fail("up is parallel to the viewing direction");
  c.focal_length_mm = n.number_or("focal_length_mm", 0.0, 0.0);
  c.sensor_height_mm = n.number_or("sensor_height_mm", 0.0, 0.0);
  if (auto f = n.find("fov_deg")) {
    c.vfov_deg = f->number(0.01, 179.0);
    if (c.focal_length_mm > 0 && c.sensor_height_mm > 0) f->fail("give either fov_deg or focal_length_mm + sensor_height_mm, not both");
    if (c.focal_length_mm > 0 && c.sensor_height_mm == 0)
      c.sensor_height_mm = 2.0 * c.focal_length_mm * std::tan(0.5 * c.vfov_deg * kPi / 180.0);
  } else if (c.focal_length_mm > 0 && c.sensor_height_mm > 0) {
    c.vfov_deg = 2.0 * std::atan(0.5 * c.sensor_height_mm / c.focal_length_mm) * 180.0 / kPi;
  } else {
    n.fail("needs fov_deg, or focal_length_mm and sensor_height_mm");
  }
  auto res = n.at("resolution");
  if (!res.is_array() || res.size() != 2) res.fail("expected [width, height]");
  c.width = res.at(0).integer(1, 16384);
  c.height = res.at(1).integer(1, 16384);
  if (c.model == CameraSpec::Model::kThinLens) {
    if (!(c.focal_length_mm > 0)) n.fail("a thin lens needs focal_length_mm");
    c.f_number = n.at("f_number").number(0.5, 1000.0);
    c.focus_distance_m = n.number_or("focus_distance_m", glm::length(c.look_at - c.position), 1e-4);
  } else {
    c.f_number = n.number_or("f_number", 0.0, 0.0);
  }
  return c;
}

}  // namespace ofl
