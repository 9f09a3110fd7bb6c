// What layered tissue costs against the surface tissue model, measured in one run on
// benchmarks/scenes/tongue_mouth_fluorescent.json (tongue_mouth.glb under four 405 nm LEDs) with the
// tongue and mouth materials replaced by
//   surface: {"type": "tissue", "preset": "tongue" | "mucosa"}           (coated albedo matrix)
//   layered: {"type": "layered_tissue", "preset": "dorsal_tongue" | "buccal_mucosa"}
// at equal samples per pixel (time ratio) and at equal noise: the relative noise of each image is
// estimated from its even and odd samples (RenderStats::relative_noise), and the time to reach a
// common noise level is time x (noise / target)^2, so the ratio at equal noise is
// (t_layered noise_layered^2) / (t_surface noise_surface^2). Best of --reps alternating runs.
//   usage: layered_cost [--spp N] [--width W] [--reps N] [--threads N] [--json]
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "renderer/core/json_node.h"
#include "renderer/render/render_job.h"

using namespace ofl;

namespace {

Scene variant(const std::string& file, bool layered, int spp, int width) {
  JsonFile f = JsonFile::load(file);
  nlohmann::json j = f.doc();
  if (layered) {
    j["materials"]["tongue"] = {{"type", "layered_tissue"}, {"preset", "dorsal_tongue"}};
    j["materials"]["mouth"] = {{"type", "layered_tissue"}, {"preset", "buccal_mucosa"}};
  } else {
    j["materials"]["tongue"] = {{"type", "tissue"}, {"preset", "tongue"}};
    j["materials"]["mouth"] = {{"type", "tissue"}, {"preset", "mucosa"}};
  }
  j["integrator"]["spp"] = spp;
  if (width > 0) {  // same field of view, fewer pixels
    auto& res = j["camera"]["resolution"];
    int w = res[0], h = res[1];
    res = {width, std::max(1, h * width / w)};
  }
  return load_scene(JsonFile::from(j, file));
}

}  // namespace

int main(int argc, char** argv) {
  int spp = 32, threads = 2, width = 0, reps = 2;
  bool json = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--spp" && i + 1 < argc) spp = std::stoi(argv[++i]);
    else if (a == "--threads" && i + 1 < argc) threads = std::stoi(argv[++i]);
    else if (a == "--width" && i + 1 < argc) width = std::stoi(argv[++i]);
    else if (a == "--reps" && i + 1 < argc) reps = std::stoi(argv[++i]);
    else if (a == "--json") json = true;
  }
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  const std::string file = std::string(OFL_SOURCE_DIR) + "/benchmarks/scenes/tongue_mouth_fluorescent.json";
  Scene surface = variant(file, false, spp, width), layered = variant(file, true, spp, width);
  RenderOptions o;
  o.progress = false;
  o.aovs = false;
  RenderStats best_s, best_l;
  best_s.seconds = best_l.seconds = 1e30;
  for (int rep = 0; rep < reps; ++rep) {
    RenderStats s = render(surface, o).stats, l = render(layered, o).stats;
    if (s.seconds < best_s.seconds) best_s = s;
    if (l.seconds < best_l.seconds) best_l = l;
  }
  double time_ratio = best_l.seconds / best_s.seconds;
  double equal_noise = (best_l.seconds * best_l.relative_noise * best_l.relative_noise) /
                       (best_s.seconds * best_s.relative_noise * best_s.relative_noise);
  nlohmann::json out = {{"scene", file}, {"spp", spp}, {"threads", threads}, {"width", width},
                        {"surface", {{"seconds", best_s.seconds}, {"relative_noise", best_s.relative_noise},
                                     {"camera_samples_per_second", best_s.samples_per_second()}}},
                        {"layered", {{"seconds", best_l.seconds}, {"relative_noise", best_l.relative_noise},
                                     {"camera_samples_per_second", best_l.samples_per_second()}}},
                        {"time_ratio_equal_samples", time_ratio}, {"time_ratio_equal_noise", equal_noise}};
  if (json) {
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    std::printf("tongue_mouth_fluorescent, %d spp, %d threads\n", spp, threads);
    std::printf("  surface tissue: %.2f s, relative noise %.4f\n", best_s.seconds, best_s.relative_noise);
    std::printf("  layered tissue: %.2f s, relative noise %.4f\n", best_l.seconds, best_l.relative_noise);
    std::printf("  time ratio at equal samples %.2fx, at equal noise %.2fx (target <= 3x)\n", time_ratio, equal_noise);
  }
  return 0;
}
