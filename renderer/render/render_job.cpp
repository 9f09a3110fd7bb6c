#include "renderer/render/render_job.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include "renderer/core/process/progress.h"
#include "renderer/render/aov_pass.h"
#include "renderer/render/spatial_checks.h"

namespace ofl {

namespace {

constexpr int kTile = 16;  // pixels per tile side: the unit of work and of an interrupted pass

// The sums a render accumulates: radiance per pixel and band, its fluorescent part, and two
// half-sums (even and odd samples) per pixel for the noise estimate.
struct Film {
  int W = 0, H = 0, B = 0, tx = 0, ty = 0;
  bool track_fl = false;
  std::vector<double> sum, sum_fl;
  std::vector<float> half;
  // Tiles that ran in the current pass (all of them unless Ctrl-C arrived during it).
  std::vector<char> tile_in_pass;
};

Film make_film(const Scene& scene, const RenderTables& tables, const RenderOptions& opt) {
  Film f;
  f.W = scene.camera.width;
  f.H = scene.camera.height;
  f.B = tables.bands;
  f.tx = (f.W + kTile - 1) / kTile;
  f.ty = (f.H + kTile - 1) / kTile;
  f.sum.assign(size_t(f.W) * f.H * f.B, 0.0);
  bool any_fluor = false;
  // Surface fluorophores or a layered stack's (a stack's fluorescence is tallied in the same layer).
  for (auto& m : tables.materials) any_fluor = any_fluor || !m.fluorophores.empty() || m.stack.fluorescent();
  f.track_fl = opt.fluorescence_layer && any_fluor;
  f.sum_fl.assign(f.track_fl ? f.sum.size() : 0, 0.0);
  f.half.assign(size_t(f.W) * f.H * 2, 0.0f);
  f.tile_in_pass.assign(size_t(f.tx) * f.ty, 0);
  return f;
}

// Doubtful scenes said before the work starts: no lights, a camera that faces nothing or sits
// inside closed geometry, spatial materials on meshes too thin for their search.
void preflight_warnings(const Scene& scene, const EmbreeScene& embree, const RenderTables& tables, RenderStats& st) {
  if (scene.lights.empty())
    st.warnings.push_back("the scene has no lights: only emissive materials, if any, light it");
  ViewProbe vp = probe_view(scene, embree);
  if (vp.hits == 0)
    st.warnings.push_back("the camera faces nothing: none of " + std::to_string(vp.rays) + " view rays hits any geometry");
  else if (vp.hits == vp.rays && vp.back_hits * 10 >= vp.rays * 9)
    st.warnings.push_back("the camera appears to be inside closed geometry: " + std::to_string(vp.back_hits) + " of " +
                          std::to_string(vp.rays) + " view rays hit the back of a surface");
  throw_if_interrupted("preparing the render; nothing was rendered");
  for (std::string& w : spatial_geometry_warnings(scene, embree, tables)) st.warnings.push_back(std::move(w));
}

// One tile's samples [first, first + pass) of every pixel, added to the film. Each sample's random
// numbers depend only on the seed, the pixel and the sample index, so the image does not depend on
// which thread ran the tile.
void render_tile(const PathTracer& tracer, const RenderOptions& opt, uint64_t seed, int tile, int first, int pass,
                 Film& f, RayCounts& local, std::vector<double>& acc, std::vector<double>& acc_fl) {
  const int x0 = (tile % f.tx) * kTile, y0 = (tile / f.tx) * kTile, B = f.B;
  for (int y = y0; y < std::min(y0 + kTile, f.H); ++y)
    for (int x = x0; x < std::min(x0 + kTile, f.W); ++x) {
      std::fill(acc.begin(), acc.end(), 0.0);
      std::fill(acc_fl.begin(), acc_fl.end(), 0.0);
      uint64_t pixel = uint64_t(y) * f.W + x;
      double h0 = 0, h1 = 0;
      for (int s = first; s < first + pass; ++s) {
        Rng rng(seed, Rng::stream_for(pixel, s));
        ((s & 1) ? h1 : h0) += tracer.sample_pixel(x, y, rng, acc.data(), local, opt.ray_log, f.track_fl ? acc_fl.data() : nullptr);
      }
      double* dst = f.sum.data() + pixel * B;
      for (int b = 0; b < B; ++b) dst[b] += acc[b];
      if (f.track_fl)
        for (int b = 0; b < B; ++b) f.sum_fl[pixel * B + b] += acc_fl[b];
      f.half[2 * pixel] += float(h0);
      f.half[2 * pixel + 1] += float(h1);
    }
}

// Relative noise of the image mean from the difference of the even and odd half-images: the
// per-pixel relative standard error.
double relative_noise(const Film& f) {
  double tot = 0, diff2 = 0;
  for (size_t p = 0; p < size_t(f.W) * f.H; ++p) {
    tot += f.half[2 * p] + f.half[2 * p + 1];
    double d = f.half[2 * p] - f.half[2 * p + 1];
    diff2 += d * d;
  }
  double npx = double(f.W) * f.H;
  double mean = tot / npx;
  return mean > 0 ? std::sqrt(diff2 / npx) / mean : 0;
}

// The film's sums as an image: each pixel over its samples, `done`, plus `partial` in the tiles that
// finished an interrupted pass (counted into st.camera_samples).
SpectralImage film_image(const Scene& scene, const Film& f, int done, int partial, RenderStats& st) {
  const int W = f.W, H = f.H, B = f.B;
  std::vector<double> inv(size_t(W) * H, done > 0 ? 1.0 / done : 0.0);
  if (partial > 0)
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        if (f.tile_in_pass[size_t(y / kTile) * f.tx + x / kTile]) {
          inv[size_t(y) * W + x] = 1.0 / (done + partial);
          st.camera_samples += uint64_t(partial);
        }
  SpectralImage img;
  std::vector<double> centres;
  for (int b = 0; b < B; ++b) centres.push_back(scene.integrator.bands.centre(b));
  img.resize(W, H, centres);
  for (size_t i = 0; i < f.sum.size(); ++i) img.data[i] = float(f.sum[i] * inv[i / size_t(B)]);
  if (f.track_fl) {
    img.fluorescence.resize(f.sum_fl.size());
    for (size_t i = 0; i < f.sum_fl.size(); ++i) img.fluorescence[i] = float(f.sum_fl[i] * inv[i / size_t(B)]);
  }
  return img;
}

}  // namespace

RenderResult render(const Scene& scene, const RenderOptions& opt) {
  auto t0 = std::chrono::steady_clock::now();
  EmbreeScene embree(scene);
  RenderTables tables(scene, opt.wavelength_importance);
  PathTracer tracer(scene, embree, tables);
  auto t1 = std::chrono::steady_clock::now();

  Film film = make_film(scene, tables, opt);
  const int W = film.W, H = film.H, B = film.B;
  const int spp = scene.integrator.spp;
  const uint64_t seed = scene.integrator.seed;

  RenderStats st;
  st.build_seconds = std::chrono::duration<double>(t1 - t0).count();
  preflight_warnings(scene, embree, tables, st);
  std::optional<ProgressBar> bar;  // RenderOptions::progress false: no bar at all
  if (opt.progress) bar.emplace("render", int64_t(W) * H * spp);
  std::mutex mu;
  int done = 0;
  // Library progress callback: called only on this thread (which takes part in the tile loop).
  const auto caller = std::this_thread::get_id();
  const int64_t total_samples = int64_t(W) * H * spp;
  std::atomic<int64_t> samples_done{0};
  auto last_call = std::chrono::steady_clock::now();
  bool stop = false;
  auto report = [&](bool force) {
    if (!opt.progress_callback || (!force && std::this_thread::get_id() != caller) || stop) return;
    auto now = std::chrono::steady_clock::now();
    if (!force && now - last_call < std::chrono::milliseconds(200)) return;
    last_call = now;
    if (!opt.progress_callback(samples_done.load(), total_samples)) stop = true;
  };
  const int max_pass = std::max(1, int(4'000'000 / (int64_t(W) * H)));
  // Ctrl-C during a pass: the tiles not yet started skip it and the tiles that finished keep it, so
  // the first signal takes effect within a tile, and no sample that was traced is thrown away
  // (those tiles hold `partial` more samples per pixel than the rest).
  int partial = 0;
  while (done < spp) {
    int pass = std::clamp(done, 1, max_pass);
    pass = std::min(pass, spp - done);
    std::fill(film.tile_in_pass.begin(), film.tile_in_pass.end(), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, film.tx * film.ty, 1), [&](const tbb::blocked_range<int>& r) {
      RayCounts local;
      local.timing = opt.time_stages;
      std::vector<double> acc(B), acc_fl(B);
      for (int tile = r.begin(); tile != r.end(); ++tile) {
        if (interrupt_requested()) continue;
        film.tile_in_pass[size_t(tile)] = 1;
        render_tile(tracer, opt, seed, tile, done, pass, film, local, acc, acc_fl);
        const int x0 = (tile % film.tx) * kTile, y0 = (tile / film.tx) * kTile;
        int64_t n = int64_t(std::min(kTile, W - x0)) * std::min(kTile, H - y0) * pass;
        if (bar) bar->advance(n);
        samples_done += n;
        report(false);
      }
      std::lock_guard lock(mu);
      st.rays += local;
    });
    if (std::find(film.tile_in_pass.begin(), film.tile_in_pass.end(), 0) != film.tile_in_pass.end()) {
      partial = pass;  // interrupted inside the pass
      st.interrupted = true;
      break;
    }
    done += pass;
    st.relative_noise = relative_noise(film);
    report(true);
    if (interrupt_requested() || stop) { st.interrupted = done < spp; break; }
    if (scene.integrator.noise_target > 0 && done >= 4 && st.relative_noise <= scene.integrator.noise_target) break;
  }
  if (bar) bar->finish();
  auto t2 = std::chrono::steady_clock::now();
  st.seconds = std::chrono::duration<double>(t2 - t1).count();
  st.spp_done = done;
  st.camera_samples = uint64_t(W) * H * done;

  RenderResult res;
  res.image = film_image(scene, film, done, partial, st);
  if (opt.aovs) {
    res.image.aovs = compute_aovs(scene, embree);
    if (res.image.aovs.empty()) {  // Ctrl-C while they were computed: the radiance is kept without them
      st.interrupted = true;
      st.warnings.push_back("interrupted before the per-pixel planes (aov.*) were complete: the image has none");
    }
  }
  if (done > 0 && std::all_of(res.image.data.begin(), res.image.data.end(), [](float v) { return v == 0.0f; }))
    st.warnings.push_back("the image is all zero: no light reached the camera");
  res.stats = st;
  describe_render(scene, st, res.image);
  return res;
}

void describe_render(const Scene& scene, const RenderStats& st, SpectralImage& img) {
  img.attributes["oralfluor.scene"] = scene.file;
  img.attributes["oralfluor.spp"] = std::to_string(st.spp_done);
  img.attributes["oralfluor.seed"] = std::to_string(scene.integrator.seed);
  img.attributes["oralfluor.vfov_deg"] = std::to_string(scene.camera.vfov_deg);
  img.attributes["oralfluor.camera_model"] = scene.camera.model == CameraSpec::Model::kThinLens ? "thin_lens" : "pinhole";
  img.attributes["oralfluor.camera_position"] = nlohmann::json({scene.camera.position.x, scene.camera.position.y, scene.camera.position.z}).dump();
  if (st.interrupted) img.attributes["oralfluor.interrupted"] = "true";
  nlohmann::json names = nlohmann::json::array();
  for (auto& m : scene.materials) names.push_back(m.name);
  img.attributes["oralfluor.materials"] = names.dump();
  // Summed on-axis radiant intensity of the LEDs, for tools that need the excitation spectrum.
  const WavelengthGrid& g = scene.grid();
  std::vector<double> nm, w(g.size(), 0.0);
  for (int i = 0; i < g.size(); ++i) nm.push_back(g.wavelength(i));
  for (const auto& l : scene.lights)
    for (int i = 0; i < g.size(); ++i) w[i] += l.spectral_intensity[i];
  img.attributes["oralfluor.excitation_spd"] = nlohmann::json({{"nm", nm}, {"W_per_sr_nm", w}}).dump();
}

BandCoverage led_light_outside_bands(const Scene& scene) {
  const WavelengthGrid& g = scene.grid();
  std::vector<double> w(g.size(), 0.0), lo, hi;
  for (const auto& l : scene.lights)
    for (int i = 0; i < g.size(); ++i) w[i] += l.spectral_intensity[i];
  const BandSet& bs = scene.integrator.bands;
  for (int b = 0; b < bs.size(); ++b) {
    lo.push_back(bs.centre(b) - 0.5 * bs.step_nm);
    hi.push_back(bs.centre(b) + 0.5 * bs.step_nm);
  }
  return band_coverage(g, w, lo, hi);
}

std::string led_band_warning(const Scene& scene) {
  const BandSet& bs = scene.integrator.bands;
  std::string w = coverage_warning(led_light_outside_bands(scene), "the LED light", bs.min_nm - 0.5 * bs.step_nm,
                                   bs.max_nm + 0.5 * bs.step_nm);
  return w.empty() ? w : w + " (integrator.output_bands; leave it out to write the whole grid)";
}

}  // namespace ofl
