// Shared machinery of the closed-form benchmark cases: building scenes in memory, exact
// references on the plane z = 0 seen by a pinhole camera, band means, and region comparisons.
#pragma once
#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "renderer/validation/harness/bench_result.h"
#include "renderer/render/render_job.h"

namespace ofl::bench {

// Band means of a spectrum tabulated on the scene's grid (box overlap of bins with bands).
// A flat 2 m quad of one material (named "m"), a 10 m-high LED of spectrum `spd` above it, a 4x4
// camera: what the layered and spatial bench cases load a stack's tables from.
Scene stack_bench_scene(const nlohmann::json& material, const nlohmann::json& spd, double min_nm, double max_nm);
std::vector<double> to_bands(const Scene& sc, const std::vector<double>& grid_values);

// Exact radiance at a point of the plane z = 0 (per band), or false where there is none.
using PlaneRadiance = std::function<bool(const glm::dvec3& p, std::vector<double>& bands)>;

struct Reference {
  std::vector<double> L;    // [pixel][band]
  std::vector<char> valid;  // pixels with a defined reference
};

// Averages the exact radiance over a 4x4 grid inside each pixel, looking at the plane z = 0;
// `blocked(camera, point)` marks pixels whose view of the plane is hidden.
Reference plane_reference(const Scene& sc, const PlaneRadiance& f,
                          const std::function<bool(const glm::dvec3&, const glm::dvec3&)>& blocked);
// Radiance of a Lambertian point of the plane z = 0 lit by a point LED: per band `per_unit` times
// P(theta) cos(theta_i) / r^2 (per_unit carries the spectrum, I0 and 1/pi).
PlaneRadiance point_led_on_plane(const LedLight& led, std::vector<double> per_unit);
// The same reference value for every pixel.
Reference uniform_reference(const Scene& sc, const std::vector<double>& bands);

using Region = std::pair<std::string, std::array<int, 4>>;  // name, x0 y0 x1 y1
BenchResult compare(const std::string& name, const Scene& sc, const SpectralImage& img, const Reference& ref,
                    const std::vector<Region>& extra_regions);

nlohmann::json base_scene(const BenchOptions& o, int max_depth, double grid_min_nm = 380, double grid_max_nm = 720,
                          double band_step_nm = 20);

struct Rendered {
  Scene scene;
  RenderResult result;
  double seconds = 0;
};
Rendered render_json(const nlohmann::json& j, const std::string& name);
BenchResult finish(BenchResult b, const Rendered& r, const BenchOptions& o);

// Direction of the pinhole camera's ray through image position (px, py) in pixels.
glm::dvec3 pinhole_dir(const CameraSpec& c, double px, double py);
// Pixel of the pinhole camera that sees world point p.
std::array<int, 2> pixel_of(const CameraSpec& c, const glm::dvec3& p);

}  // namespace ofl::bench
