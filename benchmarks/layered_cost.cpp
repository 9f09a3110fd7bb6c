// What layered tissue costs against the surface tissue model, measured in one run on
// benchmarks/scenes/tongue_mouth_fluorescent.json (tongue_mouth.glb under four 405 nm LEDs) with the
// tongue and mouth materials replaced by
//   surface: {"type": "tissue", "preset": "tongue" | "mucosa"}           (coated albedo matrix)
//   table:   {"type": "layered_tissue", "preset": "dorsal_tongue" | "buccal_mucosa"}   (transport "table")
//   walk:    the same with "transport": "walk" (the random walk at every vertex, the reference)
// at equal samples per pixel (time ratio) and at equal noise: the relative noise of each image is
// estimated from its even and odd samples (RenderStats::relative_noise), and the time to reach a
// common noise level is time x (noise / target)^2, so the ratio at equal noise is
// (t_layered noise_layered^2) / (t_surface noise_surface^2). The table's one-off build (scene load,
// RenderStats::build_seconds less the surface scene's) is reported separately and also added once
// to the table's time to the surface image's noise, twice: the first load fills the tables (cold:
// the benchmark points OFL_CACHE_DIR at an empty folder of its own), later loads of the same scene
// read them from the on-disk cache (warm: renderer/render/stack/stack_response_cache.h). Best of --reps
// runs (at least 2, so that one is warm); --walk-spp sets the walk's samples (0 = skip the walk,
// which takes minutes).
//   usage: layered_cost [--spp N] [--walk-spp N] [--width W] [--reps N] [--threads N] [--json]
#include <tbb/global_control.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/core/files/json_node.h"
#include "renderer/render/render_job.h"

using namespace ofl;

namespace {

enum class Variant { kSurface, kTable, kWalk };

Scene variant(const std::string& file, Variant v, int spp, int width) {
  JsonFile f = JsonFile::load(file);
  nlohmann::json j = f.doc();
  if (v == Variant::kSurface) {
    j["materials"]["tongue"] = {{"type", "tissue"}, {"preset", "tongue"}};
    j["materials"]["mouth"] = {{"type", "tissue"}, {"preset", "mucosa"}};
  } else {
    const char* transport = v == Variant::kTable ? "table" : "walk";
    j["materials"]["tongue"] = {{"type", "layered_tissue"}, {"preset", "dorsal_tongue"}, {"transport", transport}};
    j["materials"]["mouth"] = {{"type", "layered_tissue"}, {"preset", "buccal_mucosa"}, {"transport", transport}};
  }
  j["integrator"]["spp"] = spp;
  if (width > 0) {  // same field of view, fewer pixels
    auto& res = j["camera"]["resolution"];
    int w = res[0], h = res[1];
    res = {width, std::max(1, h * width / w)};
  }
  return load_scene(JsonFile::from(j, file));
}

// The fastest of `reps` renders; `builds` gets each render's scene-load seconds in order.
RenderStats best_of(const Scene& sc, int reps, std::vector<double>* builds = nullptr) {
  RenderOptions o;
  o.progress = false;
  o.aovs = false;
  RenderStats best;
  best.seconds = 1e30;
  for (int rep = 0; rep < reps; ++rep) {
    RenderStats s = render(sc, o).stats;
    if (builds) builds->push_back(s.build_seconds);
    if (s.seconds < best.seconds) best = s;
  }
  return best;
}

// Time to reach the surface image's noise (one-off build included when given).
double to_equal_noise(const RenderStats& s, const RenderStats& surface, double build = 0) {
  double r = s.relative_noise / surface.relative_noise;
  return build + s.seconds * r * r;
}

nlohmann::json stats_json(const RenderStats& s, int spp) {
  return {{"spp", spp}, {"seconds", s.seconds}, {"build_seconds", s.build_seconds}, {"relative_noise", s.relative_noise},
          {"camera_samples_per_second", s.samples_per_second()}};
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 32, walk_spp = 8, threads = 2, width = 0, reps = 2;
  bool json = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--spp" && i + 1 < argc) spp = std::stoi(argv[++i]);
    else if (a == "--walk-spp" && i + 1 < argc) walk_spp = std::stoi(argv[++i]);
    else if (a == "--threads" && i + 1 < argc) threads = std::stoi(argv[++i]);
    else if (a == "--width" && i + 1 < argc) width = std::stoi(argv[++i]);
    else if (a == "--reps" && i + 1 < argc) reps = std::stoi(argv[++i]);
    else if (a == "--json") json = true;
  }
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  reps = std::max(reps, 2);
  const std::filesystem::path cache = std::filesystem::temp_directory_path() / ("ofl_layered_cost_cache_" + std::to_string(::getpid()));
  std::filesystem::remove_all(cache);
  ::setenv("OFL_CACHE_DIR", cache.c_str(), 1);
  const std::string file = std::string(OFL_SOURCE_DIR) + "/benchmarks/scenes/tongue_mouth_fluorescent.json";
  RenderStats s = best_of(variant(file, Variant::kSurface, spp, width), reps);
  std::vector<double> loads;
  RenderStats t = best_of(variant(file, Variant::kTable, spp, width), reps, &loads);
  const double build = std::max(0.0, loads[0] - s.build_seconds);
  const double warm = std::max(0.0, *std::min_element(loads.begin() + 1, loads.end()) - s.build_seconds);
  nlohmann::json out = {{"scene", file}, {"threads", threads}, {"width", width},
                        {"surface", stats_json(s, spp)}, {"table", stats_json(t, spp)},
                        {"table_build_seconds", build},
                        {"table_cached_load_seconds", warm},
                        {"table_time_ratio_equal_samples", t.seconds / s.seconds},
                        {"table_time_ratio_equal_noise", to_equal_noise(t, s) / s.seconds},
                        {"table_time_ratio_equal_noise_with_build", to_equal_noise(t, s, build) / s.seconds},
                        {"table_time_ratio_equal_noise_cached", to_equal_noise(t, s, warm) / s.seconds}};
  RenderStats w;
  if (walk_spp > 0) {
    w = best_of(variant(file, Variant::kWalk, walk_spp, width), 1);
    // The surface render at the walk's samples, for the equal-samples ratio.
    RenderStats s_w = walk_spp == spp ? s : best_of(variant(file, Variant::kSurface, walk_spp, width), reps);
    out["walk"] = stats_json(w, walk_spp);
    out["walk_time_ratio_equal_samples"] = w.seconds / s_w.seconds;
    out["walk_time_ratio_equal_noise"] = to_equal_noise(w, s_w) / s_w.seconds;
  }
  std::filesystem::remove_all(cache);
  if (json) {
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  std::printf("tongue_mouth_fluorescent, %d threads\n", threads);
  std::printf("  surface tissue: %d spp, %.2f s, relative noise %.4f\n", spp, s.seconds, s.relative_noise);
  std::printf("  layered, table: %d spp, %.2f s, relative noise %.4f; table build %.2f s (first load), %.2f s (cached)\n",
              spp, t.seconds, t.relative_noise, build, warm);
  std::printf("    time ratio at equal samples %.2fx, at equal noise %.2fx (target <= 3x); with the load: %.2fx cached, %.2fx first load\n",
              double(out["table_time_ratio_equal_samples"]), double(out["table_time_ratio_equal_noise"]),
              double(out["table_time_ratio_equal_noise_cached"]), double(out["table_time_ratio_equal_noise_with_build"]));
  if (walk_spp > 0)
    std::printf("  layered, walk:  %d spp, %.2f s, relative noise %.4f; time ratio at equal samples %.2fx, at equal noise %.2fx\n",
                walk_spp, w.seconds, w.relative_noise, double(out["walk_time_ratio_equal_samples"]),
                double(out["walk_time_ratio_equal_noise"]));
  return 0;
}
