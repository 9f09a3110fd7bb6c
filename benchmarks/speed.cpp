// Speed of the path tracer on the reference scenes of shared/bench/README.md, as ratios measured in
// one run: the renderer's camera samples/s and rays/s, and Embree's own rtcIntersect1/rtcOccluded1
// throughput on the same rays (recorded from the renderer), which gives the share of render time
// spent inside Embree; and where the time goes, stage by stage, from the renderer's own clock
// marks (RayCounts in renderer/render/integrator/path_tracer.h) in a shorter render of the same scene.
//   usage: speed [--threads N] [--spp N] [--json] [scene.json ...]
// Default scenes: the matched tongue-in-mouth scene and the flat patch of benchmarks/scenes/peers/,
// and scenes/dark_spot_405.json (layered tissue).
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/render/render_job.h"

using namespace ofl;
using Clock = std::chrono::steady_clock;

namespace {

// Times Embree alone on recorded rays (intersect and occluded separately), best of 3 runs.
std::pair<double, double> embree_seconds_per_ray(const EmbreeScene& es, const RayLog& log) {
  std::vector<const RayLog::Ray*> isect, occl;
  for (auto& r : log.rays) (r.shadow ? occl : isect).push_back(&r);
  auto run = [&](const std::vector<const RayLog::Ray*>& rays, bool shadow) {
    double best = 1e30;
    for (int rep = 0; rep < 3; ++rep) {
      auto t0 = Clock::now();
      tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 4096), [&](const tbb::blocked_range<size_t>& rg) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        unsigned sink = 0;
        for (size_t i = rg.begin(); i != rg.end(); ++i) {
          const auto& r = *rays[i];
          if (shadow) {
            RTCRay ray{r.o[0], r.o[1], r.o[2], 0.0f, r.d[0], r.d[1], r.d[2], 0.0f, r.tmax, 0xFFFFFFFFu, 0, 0};
            rtcOccluded1(es.handle(), &ctx, &ray);
            sink += ray.tfar < 0;
          } else {
            RTCRayHit rh;
            rh.ray = {r.o[0], r.o[1], r.o[2], 0.0f, r.d[0], r.d[1], r.d[2], 0.0f, r.tmax, 0xFFFFFFFFu, 0, 0};
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(es.handle(), &ctx, &rh);
            sink += rh.hit.geomID;
          }
        }
        volatile unsigned keep = sink;
        (void)keep;
      });
      best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
    }
    return rays.empty() ? 0.0 : best / rays.size();
  };
  return {run(isect, false), run(occl, true)};
}

// Time-stamp ticks per second of stage_clock(), against steady_clock over 0.2 s.
double clock_ticks_per_second() {
  auto t0 = Clock::now();
  uint64_t c0 = stage_clock();
  while (Clock::now() - t0 < std::chrono::milliseconds(200)) {
  }
  return double(stage_clock() - c0) / std::chrono::duration<double>(Clock::now() - t0).count();
}

// Share of each stage in the ticks of a render with clock marks on (a quarter of the samples), and
// how much of the threads' wall time the marks cover (the rest: tile loop, film accumulation,
// scheduling, waiting for other processes on a shared machine).
nlohmann::json stage_profile(const Scene& scene, int threads) {
  Scene part = scene;
  part.integrator.spp = std::max(2, scene.integrator.spp / 4);
  RenderOptions o;
  o.progress = false;
  o.aovs = false;
  o.time_stages = true;
  RenderResult r;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    r = render(part, o);
  }
  const RayCounts& c = r.stats.rays;
  double total = 0;
  for (int i = 0; i < kStages; ++i) total += double(c.ticks[i]);
  nlohmann::json shares = nlohmann::json::array();  // in stage order
  for (int i = 0; i < kStages; ++i) shares.push_back({{"stage", stage_name(i)}, {"share", total > 0 ? c.ticks[i] / total : 0.0}});
  const double covered = total / clock_ticks_per_second() / (threads * r.stats.seconds);
  return {{"shares", shares}, {"marked_share_of_thread_time", covered},
          {"camera_samples_per_second_with_marks", r.stats.samples_per_second()}};
}

nlohmann::json measure(const std::string& file, int spp, int threads) {
  SceneOverrides ov;
  if (spp > 0) ov.spp = spp;
  Scene scene = load_scene(file, ov);
  RenderOptions opt;
  opt.progress = false;
  RenderResult full;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    full = render(scene, opt);
  }
  // Record the rays of a shorter render of the same scene (one thread, so the log keeps the order
  // in which a worker traces them), then trace exactly those rays with Embree alone.
  Scene small = scene;
  small.integrator.spp = std::max(1, scene.integrator.spp / 8);
  RayLog log;
  log.limit = 40'000'000;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
    RenderOptions o2 = opt;
    o2.ray_log = &log;
    render(small, o2);
  }
  EmbreeScene es(scene);
  std::pair<double, double> per_ray;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    per_ray = embree_seconds_per_ray(es, log);
  }
  const RenderStats& s = full.stats;
  uint64_t n_isect = s.rays.camera + s.rays.extension, n_occl = s.rays.shadow;
  double embree_s = n_isect * per_ray.first + n_occl * per_ray.second;
  size_t tris = 0;
  for (auto& m : scene.meshes) tris += m.triangle_count();
  double embree_rays_per_s = (n_isect + n_occl) / embree_s;
  return {{"scene", file},
          {"threads", threads},
          {"width", scene.camera.width},
          {"height", scene.camera.height},
          {"spp", s.spp_done},
          {"max_depth", scene.integrator.max_depth},
          {"triangles", tris},
          {"wavelengths_per_sample", kLanes},
          {"render_seconds", s.seconds},
          {"camera_samples_per_second", s.samples_per_second()},
          {"wavelength_samples_per_second", s.samples_per_second() * kLanes},
          {"rays", s.rays.total()},
          {"rays_per_camera_sample", double(s.rays.total()) / s.camera_samples},
          {"rays_per_camera_sample_by_kind",
           {{"camera", double(s.rays.camera) / s.camera_samples},
            {"extension", double(s.rays.extension) / s.camera_samples},
            {"shadow", double(s.rays.shadow) / s.camera_samples},
            {"probe", double(s.rays.probe) / s.camera_samples}}},
          {"rays_per_second", s.rays_per_second()},
          {"embree_intersect_rays_per_second", per_ray.first > 0 ? 1.0 / per_ray.first : 0.0},
          {"embree_occluded_rays_per_second", per_ray.second > 0 ? 1.0 / per_ray.second : 0.0},
          {"embree_rays_per_second_same_mix", embree_rays_per_s},
          {"share_of_time_in_embree", embree_s / s.seconds},
          {"recorded_rays", log.rays.size()},
          {"stages", stage_profile(scene, threads)}};
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 2, spp = 0;
  bool json = false;
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc) threads = std::stoi(argv[++i]);
    else if (a == "--spp" && i + 1 < argc) spp = std::stoi(argv[++i]);
    else if (a == "--json") json = true;
    else scenes.push_back(a);
  }
  if (scenes.empty()) {
    const std::string root = OFL_SOURCE_DIR;
    scenes = {root + "/benchmarks/scenes/peers/tongue_mouth_matched.json", root + "/benchmarks/scenes/peers/flat_patch_matched.json",
              root + "/scenes/dark_spot_405.json"};
  }
  nlohmann::json all = nlohmann::json::array();
  for (auto& s : scenes) {
    auto r = measure(s, spp, threads);
    all.push_back(r);
    if (!json)
      std::printf("%s: %dx%d, %d spp, %zu triangles, %d threads\n"
                  "  %.3f M camera samples/s, %.2f M wavelength samples/s (%d per sample), %.2f M rays/s (%.2f rays per sample)\n"
                  "  Embree alone on the same rays: %.2f M intersect/s, %.2f M occluded/s -> %.0f%% of render time inside Embree\n",
                  s.c_str(), r["width"].get<int>(), r["height"].get<int>(), r["spp"].get<int>(), r["triangles"].get<size_t>(), threads,
                  r["camera_samples_per_second"].get<double>() * 1e-6, r["wavelength_samples_per_second"].get<double>() * 1e-6, kLanes,
                  r["rays_per_second"].get<double>() * 1e-6, r["rays_per_camera_sample"].get<double>(),
                  r["embree_intersect_rays_per_second"].get<double>() * 1e-6, r["embree_occluded_rays_per_second"].get<double>() * 1e-6,
                  100 * r["share_of_time_in_embree"].get<double>());
    if (!json) {
      const auto& k = r["rays_per_camera_sample_by_kind"];
      std::printf("  rays per sample by kind: camera %.2f, extension %.2f, shadow %.2f, probe %.2f\n", k["camera"].get<double>(),
                  k["extension"].get<double>(), k["shadow"].get<double>(), k["probe"].get<double>());
      std::printf("  stages (clock marks, %.0f%% of thread time covered):", 100 * r["stages"]["marked_share_of_thread_time"].get<double>());
      for (auto& st : r["stages"]["shares"]) std::printf(" %s %.1f%%,", st["stage"].get<std::string>().c_str(), 100 * st["share"].get<double>());
      std::printf("\n");
    }
  }
  if (json) std::printf("%s\n", all.dump(2).c_str());
  return 0;
}
