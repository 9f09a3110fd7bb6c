// `oralfluor diagnose <folder-or-csv> --model model.json [--json] [-o outdir]`: fits the baseline
// model to measured spectra (or camera patches), tries every candidate cause with leave-one-
// group-out cross-validation against the noise floor, and reports the causes it can name.
#include <cstdio>
#include <memory>

#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"
#include "renderer/diagnose/diagnose_job.h"

namespace ofl {

namespace {

void run_diagnose(const DiagnoseJob& job) {
  DiagnoseOutcome r = run_diagnose_job(job);
  if (!job.json)
    for (auto& f : r.files) std::fprintf(stderr, "wrote %s\n", f.c_str());
  if (job.json)
    std::printf("%s\n", r.report.dump(2).c_str());
  else
    std::printf("%s", r.text.c_str());
}

}  // namespace

void register_diagnose_command(CLI::App& app) {
  auto job = std::make_shared<DiagnoseJob>();
  auto* cmd = app.add_subcommand("diagnose",
                                 "compare the model with measured spectra or camera patches, name the cause of the mismatch, "
                                 "and measure the held-out gain of the extended model");
  cmd->add_option("input", job->input, "folder with index.csv (spectra) or patches.csv (camera), or that CSV itself")->required();
  cmd->add_option("--model", job->model, "model description (JSON; see docs/diagnose.md)")->required();
  cmd->add_flag("--json", job->json, "print the JSON report on stdout");
  cmd->add_option("-o,--out", job->outdir, "write report.json, report.txt, residuals.csv and SVG plots here");
  cmd->add_option("--where", job->where, "keep only rows with column=value (value a|b for several); repeatable");
  cmd->add_option("--groups", job->groups, "cross-validation group columns (overrides the model)")->delimiter(',');
  cmd->add_option("--z", job->z, "significance of the held-out gain against the noise floor (default 3)");
  cmd->add_option("--max-causes", job->max_causes, "stop after this many causes");
  cmd->add_option("--report-by", job->report_by, "break the held-out gains down by this column (overrides the model)");
  cmd->add_option("--fit-on", job->fit_on,
                  "select causes and fit them on these rows only (column=a,b), then predict the others with the fitted "
                  "global parameters fixed (spectra)");
  cmd->add_option("--predict", job->predict, "rows to predict with --fit-on (column=a,b; default: every other row)");
  cmd->add_option("--shared-concentrations", job->shared_concentrations,
                  "spectra equal in these columns (e.g. subject,site,date) share one set of fluorophore amounts "
                  "(overrides the model; spectra)")
      ->delimiter(',');
  cmd->add_option("--tissue-per", job->tissue_per,
                  "fit tissue causes one set per value of these columns (e.g. subject), instrument causes one set for all "
                  "(overrides the model; spectra)")
      ->delimiter(',');
  cmd->callback([job] { run_diagnose(*job); });
}

}  // namespace ofl
