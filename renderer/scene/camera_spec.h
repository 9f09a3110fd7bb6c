// The render camera's geometry: pinhole or thin lens, placement, field of view, resolution.
// (The sensor, filters and noise are the camera module's job, renderer/camera/.)
#pragma once
#include <glm/vec3.hpp>

#include "renderer/core/files/json_node.h"

namespace ofl {

struct CameraSpec {
  enum class Model { kPinhole, kThinLens };
  Model model = Model::kPinhole;
  glm::dvec3 position{0, 0, 1};
  glm::dvec3 look_at{0, 0, 0};
  glm::dvec3 up{0, 1, 0};
  double vfov_deg = 40;          // vertical field of view; or derived from the two below
  double focal_length_mm = 0;    // with sensor_height_mm, sets vfov; needed for a thin lens
  double sensor_height_mm = 0;
  double f_number = 0;           // thin lens aperture: radius = focal_length / (2 N)
  double focus_distance_m = 0;   // thin lens; 0 = distance to look_at
  int width = 256, height = 256;

  double aperture_radius_m() const { return model == Model::kThinLens ? 0.5e-3 * focal_length_mm / f_number : 0.0; }
};

// {"type": "pinhole" | "thin_lens", "position", "look_at", "up", "fov_deg" | ("focal_length_mm" and
//  "sensor_height_mm"), "f_number", "focus_distance_m", "resolution": [w, h]}
CameraSpec parse_camera_spec(const JsonNode& node);

}  // namespace ofl
