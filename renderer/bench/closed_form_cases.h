// Accuracy benchmarks against closed-form answers (DESIGN.md section 7). Each case builds its
// scene in memory, renders it, and compares every pixel and band with the exact radiance.
// Errors are reported per image region: the relative error of the region's mean radiance in each
// band (bias plus the noise left after averaging the region), and the RMS per-pixel relative error
// (noise), which should fall like 1/sqrt(spp).
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/scene/scene.h"

namespace ofl {

struct BenchRegion {
  std::string name;
  double rel_error = 0;      // mean over bands of |mean(L) - mean(L_ref)| / mean(L_ref)
  double max_band_error = 0; // worst band
  int pixels = 0;
};

struct BenchResult {
  std::string name;
  int spp = 0;
  double mean_rel_error = 0;     // mean over regions and bands
  double max_rel_error = 0;      // worst region and band
  double rms_pixel_rel_error = 0;
  nlohmann::json extra = nlohmann::json::object();  // case-specific numbers
  double seconds = 0;
  double camera_samples_per_second = 0;
  std::vector<BenchRegion> regions;
  nlohmann::json to_json() const;
};

struct BenchCaseInfo {
  std::string name;
  std::string description;
  int default_spp;
};

std::vector<BenchCaseInfo> bench_cases();
struct BenchOptions {
  int spp = 64;
  uint64_t seed = 1;
  bool sampled_excitation = false;  // sample excitation wavelengths instead of summing them
  std::string importance_camera;    // sample camera wavelengths by this camera's system QE (half)
  std::string light_selection;      // integrator "light_selection" ("reach", "power"); empty: default
};

// Runs one case; throws InputError for an unknown name.
BenchResult run_bench_case(const std::string& name, const BenchOptions& options);
inline BenchResult run_bench_case(const std::string& name, int spp, uint64_t seed = 1) {
  return run_bench_case(name, BenchOptions{spp, seed, false, ""});
}

// Fluorescent cases (fluorescence_cases.cpp).
BenchResult fluorescent_patch(const BenchOptions& o, bool narrow_385);
// Layered tissue (fluorescence_cases.cpp, layered_cases.cpp).
BenchResult layered_thin_limit(const BenchOptions& o);
BenchResult layered_fluorescent_slab(const BenchOptions& o);
BenchResult layered_fluorescent_slab_table(const BenchOptions& o);
BenchResult fluorescent_sphere(const BenchOptions& o);
BenchResult reradiation_only(const BenchOptions& o);
BenchResult fluorescent_disk_led(const BenchOptions& o);
// The disk-LED geometry with any patch material; `spectrum` gives per grid bin the patch radiance
// in W sr^-1 m^-2 nm^-1 per unit of the disk's geometric factor E / L_led.
BenchResult disk_led_case(const BenchOptions& o, const std::string& name, const nlohmann::json& material,
                          const std::function<std::vector<double>(const Scene&)>& spectrum);

}  // namespace ofl
