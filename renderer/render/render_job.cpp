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

#include "renderer/core/progress.h"
#include "renderer/render/aov_pass.h"
#include "renderer/render/spatial/spatial_checks.h"

namespace ofl {

RenderResult render(const Scene& scene, const RenderOptions& opt) {
  auto t0 = std::chrono::steady_clock::now();
  EmbreeScene embree(scene);
  RenderTables tables(scene, opt.wavelength_importance);
  PathTracer tracer(scene, embree, tables);
  auto t1 = std::chrono::steady_clock::now();

  const int W = scene.camera.width, H = scene.camera.height, B = tables.bands;
  const int spp = scene.integrator.spp;
  const uint64_t seed = scene.integrator.seed;
  std::vector<double> sum(size_t(W) * H * B, 0.0);
  bool any_fluor = false;
  // Surface fluorophores or a layered stack's (a stack's fluorescence is tallied in the same layer).
  for (auto& m : tables.materials) any_fluor = any_fluor || !m.fluorophores.empty() || m.stack.fluorescent();
  const bool track_fl = opt.fluorescence_layer && any_fluor;
  std::vector<double> sum_fl(track_fl ? sum.size() : 0, 0.0);
  // Two half-sums (even and odd samples) for the noise estimate.
  std::vector<float> half(size_t(W) * H * 2, 0.0f);
  constexpr int kTile = 16;
  const int tx = (W + kTile - 1) / kTile, ty = (H + kTile - 1) / kTile;

  RenderStats st;
  st.build_seconds = std::chrono::duration<double>(t1 - t0).count();
  if (scene.lights.empty())
    st.warnings.push_back("the scene has no lights: only emissive materials, if any, light it");
  {
    ViewProbe vp = probe_view(scene, embree);
    if (vp.hits == 0)
      st.warnings.push_back("the camera faces nothing: none of " + std::to_string(vp.rays) + " view rays hits any geometry");
    else if (vp.hits == vp.rays && vp.back_hits * 10 >= vp.rays * 9)
      st.warnings.push_back("the camera appears to be inside closed geometry: " + std::to_string(vp.back_hits) + " of " +
                            std::to_string(vp.rays) + " view rays hit the back of a surface");
  }
  throw_if_interrupted("preparing the render; nothing was rendered");
  for (std::string& w : spatial_geometry_warnings(scene, embree, tables)) st.warnings.push_back(std::move(w));
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
  std::vector<char> tile_in_pass(size_t(tx) * ty, 0);
  int partial = 0;
  while (done < spp) {
    int pass = std::clamp(done, 1, max_pass);
    pass = std::min(pass, spp - done);
    std::fill(tile_in_pass.begin(), tile_in_pass.end(), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, tx * ty, 1), [&](const tbb::blocked_range<int>& r) {
      RayCounts local;
      local.timing = opt.time_stages;
      std::vector<double> acc(B), acc_fl(B);
      for (int tile = r.begin(); tile != r.end(); ++tile) {
        if (interrupt_requested()) continue;
        tile_in_pass[size_t(tile)] = 1;
        int x0 = (tile % tx) * kTile, y0 = (tile / tx) * kTile;
        for (int y = y0; y < std::min(y0 + kTile, H); ++y)
          for (int x = x0; x < std::min(x0 + kTile, W); ++x) {
            std::fill(acc.begin(), acc.end(), 0.0);
            std::fill(acc_fl.begin(), acc_fl.end(), 0.0);
            uint64_t pixel = uint64_t(y) * W + x;
            double h0 = 0, h1 = 0;
            for (int s = done; s < done + pass; ++s) {
              Rng rng(seed, Rng::stream_for(pixel, s));
              ((s & 1) ? h1 : h0) += tracer.sample_pixel(x, y, rng, acc.data(), local, opt.ray_log, track_fl ? acc_fl.data() : nullptr);
            }
            double* dst = sum.data() + pixel * B;
            for (int b = 0; b < B; ++b) dst[b] += acc[b];
            if (track_fl)
              for (int b = 0; b < B; ++b) sum_fl[pixel * B + b] += acc_fl[b];
            half[2 * pixel] += float(h0);
            half[2 * pixel + 1] += float(h1);
          }
        int64_t n = int64_t(std::min(kTile, W - x0)) * std::min(kTile, H - y0) * pass;
        if (bar) bar->advance(n);
        samples_done += n;
        report(false);
      }
      std::lock_guard lock(mu);
      st.rays += local;
    });
    if (std::find(tile_in_pass.begin(), tile_in_pass.end(), 0) != tile_in_pass.end()) {
      partial = pass;  // interrupted inside the pass
      st.interrupted = true;
      break;
    }
    done += pass;
    // Relative noise of the image mean from the difference of the even and odd half-images.
    double tot = 0, diff2 = 0;
    for (size_t p = 0; p < size_t(W) * H; ++p) {
      tot += half[2 * p] + half[2 * p + 1];
      double d = half[2 * p] - half[2 * p + 1];
      diff2 += d * d;
    }
    double npx = double(W) * H;
    double mean = tot / npx;
    st.relative_noise = mean > 0 ? std::sqrt(diff2 / npx) / mean : 0;  // per-pixel relative std error
    report(true);
    if (interrupt_requested() || stop) { st.interrupted = done < spp; break; }
    if (scene.integrator.noise_target > 0 && done >= 4 && st.relative_noise <= scene.integrator.noise_target) break;
  }
  if (bar) bar->finish();
  auto t2 = std::chrono::steady_clock::now();
  st.seconds = std::chrono::duration<double>(t2 - t1).count();
  st.spp_done = done;
  st.camera_samples = uint64_t(W) * H * done;
  // 1 / samples of each pixel: `done`, plus `partial` in the tiles that finished an interrupted pass.
  std::vector<double> inv(size_t(W) * H, done > 0 ? 1.0 / done : 0.0);
  if (partial > 0)
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        if (tile_in_pass[size_t(y / kTile) * tx + x / kTile]) {
          inv[size_t(y) * W + x] = 1.0 / (done + partial);
          st.camera_samples += uint64_t(partial);
        }

  RenderResult res;
  std::vector<double> centres;
  for (int b = 0; b < B; ++b) centres.push_back(scene.integrator.bands.centre(b));
  res.image.resize(W, H, centres);
  for (size_t i = 0; i < sum.size(); ++i) res.image.data[i] = float(sum[i] * inv[i / size_t(B)]);
  if (track_fl) {
    res.image.fluorescence.resize(sum_fl.size());
    for (size_t i = 0; i < sum_fl.size(); ++i) res.image.fluorescence[i] = float(sum_fl[i] * inv[i / size_t(B)]);
  }
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
