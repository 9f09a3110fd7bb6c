// `oralfluor sweep sweep.json [-o DIR] [--shard i/N] [--json]`: renders every design point of a
// sweep (LED placement, filters, any scene or camera field), runs the camera, computes the
// illumination and chromaticity metrics over named ROIs and writes results.csv, results.json and
// report.html. Resumable (finished points are kept and skipped), shardable, and spread over ranks
// when started under mpirun. See docs/sweep-format.md.
#include <optional>
#include <cstdio>

#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"
#include "renderer/sweep/design/sweep_spec.h"
#include "renderer/sweep/sweep_runner.h"

namespace ofl {

void register_sweep_command(CLI::App& app) {
  struct Opts {
    std::string sweep, out, shard;
    bool json = false, report_only = false, dry_run = false, plot_files = false, no_render_cache = false;
    std::optional<int> spp, width, height;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("sweep", "render and analyse a design of LED-ring, filter, scene or camera variations");
  cmd->add_option("sweep", o->sweep, "sweep description (JSON, see docs/sweep-format.md)")->required();
  cmd->add_option("-o,--out", o->out, "output folder (default: sweep-out/<sweep name>)");
  cmd->add_option("--shard", o->shard, "i/N: compute only the points whose index is i mod N (0 <= i < N), e.g. $SLURM_ARRAY_TASK_ID/N");
  // The same overrides as `render`: they replace the sweep file's "render" values (and so are part of
  // every point's key: points computed with other settings are not reused).
  cmd->add_option("--spp", o->spp, "samples per pixel (overrides the sweep's render.spp)")->check(CLI::Range(1, 1 << 24));
  cmd->add_option("--width", o->width, "image width (overrides render.width; alone it keeps the aspect ratio)")
      ->check(CLI::Range(2, 16384));
  cmd->add_option("--height", o->height, "image height (overrides render.height; alone it keeps the aspect ratio)")
      ->check(CLI::Range(2, 16384));
  cmd->add_flag("--no-render-cache", o->no_render_cache,
               "render every point, even when another point rendered the same scene (as \"render\": {\"cache\": false})");
  cmd->add_flag("--report-only", o->report_only, "write the report from the finished points, compute nothing");
  cmd->add_flag("--dry-run", o->dry_run, "list the design points and which are finished, compute nothing");
  cmd->add_flag("--plot-files", o->plot_files, "also write every metric plot as SVG and PNG under <out>/plots/");
  cmd->add_flag("--json", o->json, "print the summary as JSON");
  cmd->callback([o] {
    SweepSpec spec = load_sweep_spec(o->sweep);
    if (o->spp) spec.render.spp = *o->spp;
    if (o->no_render_cache) spec.render.cache = false;
    if (o->width || o->height) {
      spec.render.width = o->width;
      spec.render.height = o->height;
    }
    SweepRunOptions ro;
    ro.out_dir = o->out.empty() ? std::filesystem::path("sweep-out") / spec.name : std::filesystem::path(o->out);
    if (!o->shard.empty() && !parse_shard(o->shard, &ro.shard, &ro.shards))
      throw InputError("", "--shard", "expected i/N with 0 <= i < N (got \"" + o->shard + "\")");
    ro.report_only = o->report_only;
    ro.dry_run = o->dry_run;
    ro.plot_files = o->plot_files;
    ro.render_progress = true;
    SweepRunSummary s = run_sweep(spec, ro);
    if (o->dry_run) return;
    bool reporter = !s.html.empty();  // rank 0 (or the only process)
    if (reporter) {
      if (o->json) std::printf("%s\n", s.to_json().dump(2).c_str());
      else
        std::printf("%d of %d points finished (%d computed now, %d were done before) -> %s, %s, %s\n", s.finished,
                    s.design_points, s.computed, s.already_done, s.csv.c_str(), s.json.c_str(), s.html.c_str());
    }
    if (s.interrupted)
      throw Interrupted("finished points are saved in " + ro.out_dir.string() + "; run the same command again to complete the sweep");
  });
}

}  // namespace ofl
