// What a closed-form bench case reports and the options it runs with (closed_form_cases.h runs
// the cases, bench_support.h holds what they share).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

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

struct BenchOptions {
  int spp = 64;
  uint64_t seed = 1;
  bool sampled_excitation = false;  // sample excitation wavelengths instead of summing them
  std::string importance_camera;    // sample camera wavelengths by this camera's system QE (half)
  std::string light_selection;      // integrator "light_selection" ("reach", "power"); empty: default
};

}  // namespace ofl
