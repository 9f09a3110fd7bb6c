// Benchmark cases whose answer is a list of numbers, each checked against a reference (a closed
// form or MCML) with its own tolerance: the layered-tissue cases (renderer/validation/cases/layered_cases.cpp)
// and one case per MCML slab (renderer/validation/references/mcml.h). Image cases with per-pixel references are in
// closed_form_cases.h.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ofl {

struct BenchCheck {
  std::string quantity;
  double value = 0, reference = 0, tolerance = 0;
  bool pass() const;
};

struct CheckCaseResult {
  std::string name;
  long long samples = 0;
  double seconds = 0;
  std::vector<BenchCheck> checks;
  nlohmann::json extra = nlohmann::json::object();
  bool pass() const;
  nlohmann::json to_json() const;
};

struct CheckCaseInfo {
  std::string name, description;
  long long default_samples = 0;
};

std::vector<CheckCaseInfo> check_cases();
bool is_check_case(const std::string& name);
// Runs one case with `samples` walks or photons (0 = the case's default).
CheckCaseResult run_check_case(const std::string& name, long long samples, uint64_t seed);

// Tolerance for a Monte Carlo estimate against an exact reference: `rel` relative or 3 standard
// errors, whichever is larger.
inline double mc_tolerance(double rel, double reference, double se) {
  double a = rel * (reference < 0 ? -reference : reference), b = 3.0 * se;
  return a > b ? a : b;
}

}  // namespace ofl
