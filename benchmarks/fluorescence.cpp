// What fluorescence costs and what deterministic direct excitation gains, measured in one run:
// 1. At equal time, the error of next-event estimation that sums the LED spectrum over excitation
//    wavelengths (deterministic, the default) against sampling one excitation wavelength per lane
//    (efficiency = 1 / (error^2 x time); gain = ratio of efficiencies) on the closed-form patches.
// 2. Render time of a fluorescent mouth scene against the same scene with fluorescence off, at
//    equal samples per pixel.
//   usage: fluorescence [--spp N] [--json]
#include <tbb/global_control.h>

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "renderer/validation/cases/closed_form_cases.h"
#include "renderer/render/render_job.h"

using namespace ofl;

int main(int argc, char** argv) {
  int spp = 256;
  bool json = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--spp" && i + 1 < argc) spp = std::stoi(argv[++i]);
    else if (a == "--json") json = true;
  }
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
  nlohmann::json out;
  for (const char* c : {"fluorescent_patch_385", "fluorescent_patch", "reradiation_only"}) {
    BenchResult d = run_bench_case(c, BenchOptions{spp, 1, false, ""});
    BenchResult s = run_bench_case(c, BenchOptions{spp, 1, true, ""});
    double eff_d = 1.0 / (d.rms_pixel_rel_error * d.rms_pixel_rel_error * d.seconds);
    double eff_s = 1.0 / (s.rms_pixel_rel_error * s.rms_pixel_rel_error * s.seconds);
    // Error the sampled estimator would reach in the deterministic estimator's time.
    double sampled_err_equal_time = s.rms_pixel_rel_error * std::sqrt(s.seconds / d.seconds);
    out["direct_excitation"][c] = {{"spp", spp},
                                   {"deterministic_rms_error", d.rms_pixel_rel_error}, {"deterministic_seconds", d.seconds},
                                   {"sampled_rms_error", s.rms_pixel_rel_error}, {"sampled_seconds", s.seconds},
                                   {"sampled_rms_error_at_equal_time", sampled_err_equal_time},
                                   {"efficiency_gain", eff_d / eff_s}};
    if (!json)
      std::printf("%-22s %d spp: deterministic %.3f%% RMS in %.2f s, sampled %.3f%% in %.2f s -> at equal time %.3f%% vs %.3f%%, efficiency gain %.1fx\n",
                  c, spp, 100 * d.rms_pixel_rel_error, d.seconds, 100 * s.rms_pixel_rel_error, s.seconds, 100 * d.rms_pixel_rel_error,
                  100 * sampled_err_equal_time, eff_d / eff_s);
  }
  std::string file = std::string(OFL_SOURCE_DIR) + "/benchmarks/scenes/tongue_mouth_fluorescent.json";
  SceneOverrides ov;
  ov.spp = 32;
  Scene on = load_scene(file, ov);
  Scene off = on;
  off.integrator.fluorescence = false;
  RenderOptions o;
  o.progress = false;
  double t_on = 1e30, t_off = 1e30;
  for (int rep = 0; rep < 2; ++rep) {  // best of two, alternating, to damp machine noise
    t_off = std::min(t_off, render(off, o).stats.seconds);
    t_on = std::min(t_on, render(on, o).stats.seconds);
  }
  out["fluorescence_cost"] = {{"scene", file}, {"spp", 32}, {"seconds_with", t_on}, {"seconds_without", t_off}, {"ratio", t_on / t_off}};
  if (json) std::printf("%s\n", out.dump(2).c_str());
  else std::printf("fluorescence cost on %s at 32 spp: %.2f s with, %.2f s without -> %.2fx\n", file.c_str(), t_on, t_off, t_on / t_off);
  return 0;
}
