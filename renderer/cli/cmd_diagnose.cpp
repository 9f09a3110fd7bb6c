// `oralfluor diagnose <folder-or-csv> --model model.json [--json] [-o outdir]`: fits the baseline
// model to measured spectra (or camera patches), tries every candidate cause with leave-one-
// group-out cross-validation against the noise floor, and reports the causes it can name.
#include <cstdio>
#include <memory>

#include "renderer/cli/commands.h"
#include "renderer/core/error.h"
#include "renderer/diagnose/camera_model.h"
#include "renderer/diagnose/diagnose_model.h"
#include "renderer/diagnose/diagnose_report.h"
#include "renderer/diagnose/forward_model.h"

namespace ofl {

namespace {

void run_diagnose(const DiagnoseJob& job) {
  DiagnoseModelFile m = load_diagnose_model(job.model);
  InputKind kind = detect_input_kind(job.input);
  if (kind != m.kind)
    throw InputError(job.model, "/kind",
                     std::string("the model is for ") + (m.kind == InputKind::kCamera ? "camera patches" : "spectra") +
                         " but " + job.input + " holds " + (kind == InputKind::kCamera ? "camera patches" : "spectra"));
  std::vector<RowFilter> select = m.select;
  for (auto& w : job.where) select.push_back(parse_where(w));
  SelectionOptions sel = m.selection;
  if (!job.groups.empty()) sel.group_columns = job.groups;
  if (job.z) sel.z = *job.z;
  if (job.max_causes) sel.max_causes = *job.max_causes;
  if (!job.report_by.empty()) sel.report_by = job.report_by;

  std::unique_ptr<DiagnoseProblem> problem;
  ReportContext ctx;
  ctx.job = job.to_json();
  ctx.input = job.input;
  ctx.model_file = job.model;
  if (kind == InputKind::kSpectra) {
    SpectraSet data = read_spectra_index(job.input, m.file_column, select);
    ctx.notes = data.notes;
    ctx.model_options = {{"blood_excitation_path_factor", m.spectra.candidates.blood_excitation_path_factor},
                         {"fit_range_nm", {m.spectra.fit_min_nm, m.spectra.fit_max_nm}},
                         {"fluorophores", m.spectra.fluorophores}};
    problem = std::make_unique<SpectraProblem>(std::move(data), std::move(m.spectra));
  } else {
    CameraPatchSet data = read_camera_patches(job.input, select);
    ctx.notes = data.notes;
    problem = std::make_unique<CameraProblem>(std::move(data), std::move(m.camera));
  }
  for (auto& c : sel.group_columns)
    if (problem->num_items() > 0 && problem->condition(0, c).empty()) {
      bool any = false;
      for (int i = 0; i < problem->num_items() && !any; ++i) any = !problem->condition(i, c).empty();
      if (!any) throw InputError(job.model, "/groups", "column \"" + c + "\" is empty or missing for every item");
    }
  Diagnosis d = diagnose(*problem, sel);
  if (!job.outdir.empty()) {
    auto files = write_diagnosis_files(*problem, d, ctx, job.outdir);
    if (!job.json)
      for (auto& f : files) std::fprintf(stderr, "wrote %s\n", f.c_str());
  }
  if (job.json)
    std::printf("%s\n", diagnosis_json(*problem, d, ctx).dump(2).c_str());
  else
    std::printf("%s", diagnosis_text(*problem, d, ctx).c_str());
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
  cmd->callback([job] { run_diagnose(*job); });
}

}  // namespace ofl
