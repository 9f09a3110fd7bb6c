// Accuracy benchmarks against closed-form answers (docs/transport.md, "How it is checked"). Each case builds its
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

#include "renderer/validation/harness/bench_result.h"
#include "renderer/scene/scene.h"

namespace ofl {

struct BenchCaseInfo {
  std::string name;
  std::string description;
  int default_spp;
};

std::vector<BenchCaseInfo> bench_cases();

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
