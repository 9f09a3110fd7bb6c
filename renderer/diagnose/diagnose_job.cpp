#include "renderer/diagnose/diagnose_job.h"

#include <memory>

#include "renderer/core/error.h"
#include "renderer/diagnose/camera_model.h"
#include "renderer/diagnose/diagnose_report.h"
#include "renderer/diagnose/forward_model.h"

namespace ofl {

DiagnoseOutcome run_diagnose_job(const DiagnoseJob& job) {
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
  DiagnoseOutcome out;
  if (!job.outdir.empty()) out.files = write_diagnosis_files(*problem, d, ctx, job.outdir);
  out.report = diagnosis_json(*problem, d, ctx);
  out.text = diagnosis_text(*problem, d, ctx);
  return out;
}

}  // namespace ofl
