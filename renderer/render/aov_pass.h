// Per-pixel auxiliary planes from one deterministic ray through each pixel centre: what the pixel
// sees (material index, UV, distance, cosine to the viewer) and the LED irradiance falling there
// (W m^-2 over the grid, with shadows). Analysis uses them for ROIs (a material, a texture region)
// and for irradiance non-uniformity.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "renderer/render/trace/embree_scene.h"

namespace ofl {

// Planes named "aov.material" (index into Scene::materials; -1 nothing, -2 an LED), "aov.u",
// "aov.v", "aov.depth" (m), "aov.cos_view", "aov.irradiance" (W m^-2). Empty when SIGINT arrives
// while they are computed (rows left are skipped: no plane is ever half filled).
std::map<std::string, std::vector<float>> compute_aovs(const Scene& scene, const EmbreeScene& embree);

// What the camera looks at, from n x n pinhole rays spread over the frame: how many hit anything and
// how many of those hit the back (against the authored normal) of a surface. The render warns when
// nothing is hit (the camera faces nothing) and when nearly every ray hits a back face (the camera
// is inside closed geometry).
struct ViewProbe {
  int rays = 0, hits = 0, back_hits = 0;
};
ViewProbe probe_view(const Scene& scene, const EmbreeScene& embree, int n = 16);

// The points each LED is integrated over: its position for a point LED, a fixed 3 x 3 stratified
// pattern on the disc of a disc LED.
std::vector<std::vector<glm::dvec3>> led_sample_points(const Scene& scene);
// LED irradiance at the surface point (W m^-2, all lights, shadowed), each LED the mean over its
// points (led_sample_points).
double led_irradiance(const Scene& scene, const EmbreeScene& embree, const SurfacePoint& sp,
                      const std::vector<std::vector<glm::dvec3>>& points);

}  // namespace ofl
