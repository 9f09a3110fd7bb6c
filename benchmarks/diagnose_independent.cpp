// Recall, false alarms and parameter coverage of `diagnose` on data made by a generator
// independent of its forward model (tests/independent_spectra.h), per hidden cause, with 95 %
// bounds (Wilson score interval).
//   usage: diagnose_independent [seeds per effect] [effect ...]
//   effect: a name below, "null" (the null rows), "name/shape" (unknown band shapes), "/edge",
//   "/response", "/edge_width", "/blur" (null data, instrument slightly wrong), "name@size" (fixed
//   size, sign alternating), "name+noleak" (the model has no leak column and the data no white-target
//   leak: the leak candidate is computed from the LED spectra and the long-pass)
// Prints a markdown table (the rows of benchmarks/results.d/25_diagnose_independent.md).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "renderer/diagnose/selection/cross_validation.h"
#include "tests/independent_spectra.h"

using namespace ofl;

namespace {

struct Expect {
  std::string effect, cause, quantity;
  double tolerance;   // absolute, on `quantity`
  std::string label;  // the row's name for null data (no effect)
};

// Wilson score interval for k successes in n trials (95 %).
std::pair<double, double> wilson(int k, int n) {
  if (n == 0) return {0, 1};
  const double z = 1.959964, p = double(k) / n, d = 1 + z * z / n;
  double c = (p + z * z / (2 * n)) / d, h = z * std::sqrt(p * (1 - p) / n + z * z / (4.0 * n * n)) / d;
  return {std::max(0.0, c - h), std::min(1.0, c + h)};
}

std::string rate(int k, int n) {
  auto [lo, hi] = wilson(k, n);
  char b[96];
  std::snprintf(b, sizeof b, "%d/%d (%.2f-%.2f)", k, n, lo, hi);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  int seeds = argc > 1 ? std::atoi(argv[1]) : 6;
  std::vector<Expect> all = {
      {"emission_shift", "emission_shift", "delta_nm", 0.3},
      {"emission_shift:FAD", "emission_shift:FAD", "delta_nm", 0.3},
      {"wavelength_shift", "wavelength_shift", "delta_nm", 0.3},
      {"offset", "stray_light", "fraction", 0.1},  // relative
      {"offset_peak", "stray_light", "fraction_of_peak", 0.1},  // relative
      {"excitation_leak", "longpass_leak", "effective_od", 0.0414},
      {"excitation_leak+noleak", "longpass_leak", "effective_od", 0.0414},
      {"unknown_fluorophore", "unknown_band", "center_nm", 5.0},
      {"unknown_fluorophore/wavelength", "unknown_band", "center_nm", 5.0},
      {"unknown_fluorophore/skewed", "unknown_band", "center_nm", 5.0},
      {"subset_chlorophyll", "extra_fluorophore:chlorophyll_a", "", 0},
      {"", "", "", 0, "none (null data)"},
      {"/edge", "", "", 0, "none, long-pass edge 1.5 nm off the model's"},
      {"/response", "", "", 0, "none, responsivity tilted +-6 %"},
      {"/edge_width", "", "", 0, "none, long-pass rising over 7.5 nm, not 5"},
      {"/blur", "", "", 0, "none, 3 nm more instrument blur"},
  };
  std::vector<Expect> run;
  for (int a = 2; a < argc; ++a)  // "emission_shift@1": that effect at a fixed size (sign alternating)
    if (const char* at = std::strchr(argv[a], '@'))
      for (auto& e : all)
        if (e.effect == std::string(argv[a], static_cast<size_t>(at - argv[a]))) {
          Expect x = e;
          x.effect = argv[a];
          run.push_back(x);
        }
  for (int a = 2; a < argc; ++a)
    for (auto& e : all)
      if (e.effect == argv[a] || (std::string(argv[a]) == "null" && (e.effect.empty() || e.effect[0] == '/'))) run.push_back(e);
  if (run.empty()) run = all;
  std::printf("| hidden effect | runs | named first | named first, nothing else | parameter within tolerance | tissue cause claimed |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (auto& e : run) {
    int first = 0, only = 0, params = 0, tissue = 0;
    for (int s = 0; s < seeds; ++s) {
      indep::Options o;
      o.effect = e.effect;
      if (auto slash = e.effect.find('/'); slash != std::string::npos) {  // effect/band shape, or /instrument error
        o.effect = e.effect.substr(0, slash);
        (o.effect.empty() ? o.instrument_error : o.band_shape) = e.effect.substr(slash + 1);
      }
      if (auto at = o.effect.find('@'); at != std::string::npos) {  // effect@size: fixed size, sign alternating
        o.magnitude = std::atof(o.effect.c_str() + at + 1) * (s % 2 ? -1 : 1);
        o.effect = o.effect.substr(0, at);
      }
      if (auto plus = o.effect.find("+noleak"); plus != std::string::npos) {  // no measured leak in model or data
        o.effect = o.effect.substr(0, plus);
        o.model_leak = "none";
        o.white_leak = 0;
      }
      const bool null_data = o.effect.empty();
      o.seed = 1000 + 37 * s;
      indep::Data d = indep::make_independent(o);
      SpectraProblem p(d.set, d.model);
      SelectionOptions so;
      so.group_columns = {"subject"};
      so.replicate_columns = {"subject", "site", "light_nm"};
      so.max_causes = 3;
      so.parallel = true;
      Diagnosis dg = diagnose(p, so);
      std::string named = dg.causes.empty() ? "" : p.candidates()[dg.causes[0].candidate].id;
      bool ok_first = named == e.cause;
      bool claimed = false;
      for (auto& c : dg.causes) claimed = claimed || (null_data && !p.candidates()[c.candidate].instrument);
      tissue += claimed;
      if (null_data) {
        std::fprintf(stderr, "null%s seed %d: %s\n", e.effect.c_str(), s, dg.verdict.c_str());
        continue;
      }
      first += ok_first;
      only += ok_first && dg.causes.size() == 1;
      bool pok = false;
      if (ok_first && !e.quantity.empty()) {
        double v = cause_estimate(p, dg.causes[0], e.quantity).value;
        double t = e.quantity == "center_nm" ? d.truth.at("peak_nm") : d.truth.at(e.quantity);
        double tol = e.quantity == "fraction" || e.quantity == "fraction_of_peak" ? e.tolerance * t : e.tolerance;
        pok = std::fabs(v - t) <= tol;
        std::fprintf(stderr, "%s seed %d: %s = %.4g (truth %.4g) | %s\n", e.effect.c_str(), s, e.quantity.c_str(), v, t, dg.verdict.c_str());
      } else if (ok_first) {
        auto& car = dg.causes[0].trial.carriers;
        pok = std::find(car.begin(), car.end(), d.carrier) != car.end();
        std::fprintf(stderr, "%s seed %d: carriers found %zu (truth %s) | %s\n", e.effect.c_str(), s, car.size(), d.carrier.c_str(), dg.verdict.c_str());
      } else {
        std::string truth;
        for (auto& [k, v] : d.truth) truth += " " + k + " " + std::to_string(v);
        std::fprintf(stderr, "%s seed %d (truth:%s): %s\n", e.effect.c_str(), s, truth.c_str(), dg.verdict.c_str());
      }
      params += pok;
    }
    if (!e.label.empty())
      std::printf("| %s | %d | | | | %s |\n", e.label.c_str(), seeds, rate(tissue, seeds).c_str());
    else
      std::printf("| %s | %d | %s | %s | %s | |\n", e.effect.c_str(), seeds, rate(first, seeds).c_str(), rate(only, seeds).c_str(),
                  rate(params, seeds).c_str());
    std::fflush(stdout);
  }
  return 0;
}
