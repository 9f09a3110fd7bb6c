// Turning one design point into the scene and camera documents to render: the base scene and
// camera JSON, edited in memory at JSON pointers, by named variants, and by the LED-rig generators
// that need more than one edit:
//   led_count           lights[i].count                       (an "led_ring")
//   ring_radius         lights[i].ring_radius_m               (m)
//   led_tilt            lights[i].tilt_deg, drops aim_distance_m (degrees toward the ring axis)
//   rig_distance        distance (m) from the camera to its look_at point: the camera and every
//                       light move together along the camera -> look_at line (a rigid rig: LED
//                       axes keep their directions; look_at stays on the tissue, so a thin lens
//                       stays focused there)
//   led_half_angle      lights[i].profile = {"half_angle_deg": v}
//   led_filter_edge     lights[i].filter.edge_nm              (the LED's short-pass, nm)
//   camera_filter_edge  camera filters[k].edge_nm             (k = "filter", default the first long-pass)
//   led_fwhm            lights[i].spd = Gaussian of this FWHM (nm) at "peak_nm" (default: the
//                       LED's own Gaussian peak)
//   scene_file, camera_file   another base scene / camera file (path relative to the sweep file)
// The edited documents keep the base files' names, so relative asset paths resolve as in the files.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/sweep/design/sweep_spec.h"

namespace ofl {

struct PointDocuments {
  nlohmann::json scene, camera;
  std::filesystem::path scene_file, camera_file;  // names the documents keep (for relative paths and errors)
};

// Sets `value` at `pointer` (the parent must exist; a null value removes the member). Throws
// InputError naming `file`/`field` (the sweep parameter) when the pointer does not fit the document.
void set_at_pointer(nlohmann::json& doc, const std::string& pointer, const nlohmann::json& value,
                    const std::string& file, const std::string& field);

// The documents for one design point: base files (or the files a scene_file/camera_file parameter
// picks), then every parameter's edit in the order of the sweep file.
PointDocuments point_documents(const SweepSpec& spec, const std::vector<nlohmann::json>& values);

// Individual edits, public for tests.
void apply_parameter(const SweepParameter& p, const nlohmann::json& value, PointDocuments& docs, const std::string& sweep_file);
void move_rig_to_distance(nlohmann::json& scene, double distance_m);

}  // namespace ofl
