// Runs a render: TBB over 16x16 tiles, samples in passes (so an interrupted render keeps every
// completed pass and a noise target can stop early), progress on stderr, ray and time statistics.
// Produces the spectral radiance image on the scene's output bands.
#pragma once
#include <cstdint>
#include <functional>

#include "renderer/image/spectral_image.h"
#include "renderer/render/integrator/path_tracer.h"
#include "renderer/scene/scene.h"
#include "renderer/spectral/spectra/band_coverage.h"

namespace ofl {

struct RenderOptions {
  bool progress = true;              // progress bar (only shown on a terminal anyway)
  RayLog* ray_log = nullptr;         // record rays (benchmarks)
  bool time_stages = false;          // clock ticks per stage in RenderStats::rays.ticks (benchmarks)
  std::vector<double> wavelength_importance;  // optional, per grid index (mixed half and half with uniform)
  bool aovs = true;                  // per-pixel material, UV, depth, irradiance planes
  bool fluorescence_layer = true;    // the fluorescent part of the radiance as its own layer
  // Optional, for library callers (the Python module): called on the calling thread about every
  // 0.2 s and after each pass with (camera samples done, samples requested). Returning false stops
  // the render after the current pass, as SIGINT does; the image keeps every completed pass.
  std::function<bool(int64_t done, int64_t total)> progress_callback;
};

struct RenderStats {
  double seconds = 0;           // wall time of tracing (excludes scene building)
  double build_seconds = 0;     // Embree BVH and tables
  int spp_done = 0;
  uint64_t camera_samples = 0;
  RayCounts rays;
  bool interrupted = false;
  double relative_noise = 0;    // estimated relative standard error of the mean band radiance
  // Doubtful success said out loud (docs/bad-inputs.md): no lights, a camera that faces nothing
  // or sits inside closed geometry, an all-zero image. The CLI prints them and render.json lists them.
  std::vector<std::string> warnings;
  double samples_per_second() const { return seconds > 0 ? camera_samples / seconds : 0; }
  double rays_per_second() const { return seconds > 0 ? rays.total() / seconds : 0; }
};

struct RenderResult {
  SpectralImage image;  // W sr^-1 m^-2 nm^-1 on the output bands
  RenderStats stats;
};

RenderResult render(const Scene& scene, const RenderOptions& options = {});

// String header attributes describing the render (scene, spp, seed, camera, LED spectra).
void describe_render(const Scene& scene, const RenderStats& stats, SpectralImage& image);

// Share of the LEDs' summed spectrum outside the scene's output bands: that light is rendered but
// not written, so no camera can see it (an excitation leak through the emission filter, say).
BandCoverage led_light_outside_bands(const Scene& scene);
// The warning for it ("" when at most 1 %), naming the range and the share.
std::string led_band_warning(const Scene& scene);

}  // namespace ofl
