// `oralfluor bench`: accuracy against closed-form cases. `--list` names them; `bench CASE --json`
// prints one JSON object; without --json a table of the error per region and how it falls with
// samples per pixel (spp/16, spp/4, spp).
#include <cmath>
#include <cstdio>

#include "renderer/validation/harness/bench_check.h"
#include "renderer/validation/cases/closed_form_cases.h"
#include "renderer/validation/references/mcml.h"
#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"

namespace ofl {

void register_bench_command(CLI::App& app) {
  struct Opts {
    std::string name;
    int spp = 0;
    uint64_t seed = 1;
    bool json = false, list = false, sampled = false;
    std::string mci, mco;
    long long samples = 0;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("bench", "accuracy of the renderer against closed-form cases");
  cmd->add_option("case", o->name, "case name (see --list)");
  cmd->add_flag("--list", o->list, "list the cases");
  cmd->add_option("--spp", o->spp, "samples per pixel (default: the case's)")->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--seed", o->seed, "random seed")->check(uint64_validator());
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->add_flag("--sampled-excitation", o->sampled, "sample excitation wavelengths in next-event estimation instead of summing them");
  cmd->add_option("--samples", o->samples, "walks or photons for the layered and MCML cases (default: the case's)")
      ->check(CLI::Range(1LL, 1LL << 40));
  cmd->add_option("--mci", o->mci, "case \"mcml\": any MCML input file (every run in it)");
  cmd->add_option("--mco", o->mco, "case \"mcml\": MCML's output for that input, to compare with");
  cmd->callback([o] {
    if (o->list || o->name.empty()) {
      for (auto& c : bench_cases()) std::printf("%-26s %s (default %d spp)\n", c.name.c_str(), c.description.c_str(), c.default_spp);
      for (auto& c : check_cases())
        std::printf("%-26s %s (default %lld samples)\n", c.name.c_str(), c.description.c_str(), c.default_samples);
      std::printf("%-26s any MCML slab: oralfluor bench mcml --mci case.mci [--mco case.mco]\n", "mcml");
      return;
    }
    if (o->name == "mcml" || is_check_case(o->name)) {
      std::vector<CheckCaseResult> rs;
      if (o->name == "mcml") {
        if (o->mci.empty()) throw InputError("", "--mci", "the mcml case needs an MCML input file (--mci case.mci)");
        auto runs = read_mci(o->mci);
        std::optional<McmlOutput> ref;
        if (!o->mco.empty()) ref = read_mco(o->mco);
        for (const auto& in : runs) {
          const long long n = o->samples > 0 ? o->samples : in.photons;
          rs.push_back(mcml_case(in, ref ? &*ref : nullptr, n, o->seed));
          // With radial resolution in MCML's output: the lateral profile the spatial transport uses.
          if (ref && ref->rd_r.size() > 1 && ref->dr_cm > 0) rs.push_back(mcml_radial_case(in, *ref, n, o->seed));
        }
      } else {
        rs.push_back(run_check_case(o->name, o->samples, o->seed));
      }
      bool pass = true;
      for (const auto& r : rs) {
        pass = pass && r.pass();
        if (o->json) {
          std::printf("%s\n", r.to_json().dump(2).c_str());
          continue;
        }
        std::printf("case %s: %lld samples, %.2f s\n\n%-56s %12s %12s %12s  %s\n", r.name.c_str(), r.samples, r.seconds, "quantity",
                    "oralfluor", "reference", "tolerance", "");
        for (const auto& c : r.checks)
          std::printf("%-56s %12.6g %12.6g %12.3g  %s\n", c.quantity.c_str(), c.value, c.reference, c.tolerance, c.pass() ? "ok" : "FAIL");
        if (r.checks.empty()) std::printf("%s\n", r.extra.dump(2).c_str());
        std::printf("\n");
      }
      if (!pass) throw std::runtime_error("accuracy check failed (see FAIL above)");
      return;
    }
    int spp = o->spp;
    if (spp == 0)
      for (auto& c : bench_cases())
        if (c.name == o->name) spp = c.default_spp;
    if (spp == 0) spp = 64;
    if (o->json) {
      std::printf("%s\n", run_bench_case(o->name, BenchOptions{spp, o->seed, o->sampled, ""}).to_json().dump(2).c_str());
      return;
    }
    std::vector<int> series;
    for (int s : {spp / 16, spp / 4, spp})
      if (s >= 1 && (series.empty() || s != series.back())) series.push_back(s);
    std::vector<BenchResult> rs;
    for (int s : series) rs.push_back(run_bench_case(o->name, BenchOptions{s, o->seed, o->sampled, ""}));
    std::printf("case %s: relative error of the region-mean radiance (mean over bands)\n\n%-16s %8s", o->name.c_str(), "region", "pixels");
    for (auto& r : rs) std::printf("  %5d spp", r.spp);
    std::printf("\n");
    for (size_t i = 0; i < rs.back().regions.size(); ++i) {
      std::printf("%-16s %8d", rs.back().regions[i].name.c_str(), rs.back().regions[i].pixels);
      for (auto& r : rs) std::printf("  %8.3f%%", i < r.regions.size() ? 100 * r.regions[i].rel_error : NAN);
      std::printf("\n");
    }
    std::printf("%-16s %8s", "mean", "");
    for (auto& r : rs) std::printf("  %8.3f%%", 100 * r.mean_rel_error);
    std::printf("\n%-16s %8s", "max (band)", "");
    for (auto& r : rs) std::printf("  %8.3f%%", 100 * r.max_rel_error);
    std::printf("\n%-16s %8s", "RMS per pixel", "");
    for (auto& r : rs) std::printf("  %8.3f%%", 100 * r.rms_pixel_rel_error);
    std::printf("\n%-16s %8s", "seconds", "");
    for (auto& r : rs) std::printf("  %9.2f", r.seconds);
    std::printf("\n");
    if (rs.size() >= 2) {
      double slope = std::log(rs.back().rms_pixel_rel_error / rs.front().rms_pixel_rel_error) / std::log(double(rs.back().spp) / rs.front().spp);
      std::printf("\nper-pixel error falls as spp^%.2f (Monte Carlo: -0.50)\n", slope);
    }
  });
}

}  // namespace ofl
