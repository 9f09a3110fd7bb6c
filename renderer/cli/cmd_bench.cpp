// `oralfluor bench`: accuracy against closed-form cases. `--list` names them; `bench CASE --json`
// prints one JSON object; without --json a table of the error per region and how it falls with
// samples per pixel (spp/16, spp/4, spp).
#include <cmath>
#include <cstdio>

#include "renderer/bench/closed_form_cases.h"
#include "renderer/cli/commands.h"

namespace ofl {

void register_bench_command(CLI::App& app) {
  struct Opts {
    std::string name;
    int spp = 0;
    uint64_t seed = 1;
    bool json = false, list = false, sampled = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("bench", "accuracy of the renderer against closed-form cases");
  cmd->add_option("case", o->name, "case name (see --list)");
  cmd->add_flag("--list", o->list, "list the cases");
  cmd->add_option("--spp", o->spp, "samples per pixel (default: the case's)")->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--seed", o->seed, "random seed");
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->add_flag("--sampled-excitation", o->sampled, "sample excitation wavelengths in next-event estimation instead of summing them");
  cmd->callback([o] {
    if (o->list || o->name.empty()) {
      for (auto& c : bench_cases()) std::printf("%-22s %s (default %d spp)\n", c.name.c_str(), c.description.c_str(), c.default_spp);
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
