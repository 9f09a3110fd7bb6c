#include "renderer/diagnose/diagnose_job.h"

#include <memory>

#include "renderer/core/error.h"
#include "renderer/core/atomic_file.h"
#include "renderer/core/progress.h"
#include "renderer/diagnose/camera_model.h"
#include "renderer/diagnose/cross_subject.h"
#include "renderer/diagnose/unknown_band.h"
#include "renderer/diagnose/diagnose_report.h"
#include "renderer/diagnose/forward_model.h"

namespace ofl {

namespace {
// The forward model names its model file "model" in errors: say which file it is.
std::unique_ptr<SpectraProblem> spectra_problem(SpectraSet data, SpectraModel model, const std::string& model_file) {
  try {
    return std::make_unique<SpectraProblem>(std::move(data), std::move(model));
  } catch (const InputError& e) {
    if (e.file() != "model") throw;
    throw InputError(model_file, e.field(), e.what());
  }
}
}  // namespace

DiagnoseOutcome run_diagnose_job(const DiagnoseJob& job) {
  DiagnoseModelFile m = load_diagnose_model(job.model);
  throw_if_interrupted("loading the model; no report was written");
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
  if (!job.shared_concentrations.empty()) m.spectra.shared_by = job.shared_concentrations;

  std::unique_ptr<DiagnoseProblem> problem;
  ReportContext ctx;
  ctx.job = job.to_json();
  ctx.input = job.input;
  ctx.model_file = job.model;
  std::unique_ptr<SpectraProblem> target;  // --fit-on: the spectra to predict
  if (!job.fit_on.empty() && kind != InputKind::kSpectra)
    throw InputError("command line", "--fit-on", "fitting on some rows and predicting others is for spectra");
  if (!job.predict.empty() && job.fit_on.empty()) throw InputError("command line", "--predict", "needs --fit-on");
  if (kind == InputKind::kSpectra && !job.fit_on.empty()) {
    auto comma_to_bar = [](std::string s) { for (char& c : s) if (c == ',') c = '|'; return s; };
    RowFilter fit = parse_where(comma_to_bar(job.fit_on));
    std::vector<RowFilter> pred_sel = select;
    if (!job.predict.empty()) {
      pred_sel.push_back(parse_where(comma_to_bar(job.predict)));
    }
    SpectraSet pred = read_spectra_index(job.input, m.file_column, pred_sel);
    // Without --predict: every selected row that --fit-on does not take.
    if (job.predict.empty())
      std::erase_if(pred.spectra, [&](const MeasuredSpectrum& s) {
        auto it = s.conditions.find(fit.column);
        std::string cell = it == s.conditions.end() ? std::string() : it->second;
        for (auto& v : fit.values)
          if (cell_matches(cell, v)) return true;
        return false;
      });
    if (pred.spectra.empty()) throw InputError("command line", "--predict", "no rows left to predict");
    select.push_back(fit);
    target = spectra_problem(std::move(pred), m.spectra, job.model);
  }
  if (kind == InputKind::kSpectra) {
    SpectraSet data = read_spectra_index(job.input, m.file_column, select);
    ctx.notes = data.notes;
    ctx.model_options = {{"blood_excitation_path_factor", m.spectra.candidates.blood_excitation_path_factor},
                         {"fit_range_nm", {m.spectra.fit_min_nm, m.spectra.fit_max_nm}},
                         {"fluorophores", m.spectra.fluorophores},
                         {"shared_concentrations", m.spectra.shared_by}};
    problem = spectra_problem(std::move(data), std::move(m.spectra), job.model);
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
  if (kind == InputKind::kSpectra) {
    UnknownBandReport ub = unknown_band_report(static_cast<const SpectraProblem&>(*problem), d);
    if (ub.estimate.found) {
      out.report["unknown_band_estimate"] = unknown_band_json(ub);
      out.text += unknown_band_text(ub);
      if (!job.outdir.empty()) {
        auto f = std::filesystem::path(job.outdir) / "unknown_band.svg";
        write_file_atomic(f, unknown_band_svg(ub));
        out.files.push_back(f.string());
      }
    }
  }
  if (target) {
    CrossSubjectPrediction c = predict_other_subjects(static_cast<const SpectraProblem&>(*problem), d, *target);
    c.fit_on = job.fit_on;
    c.predict = job.predict.empty() ? "every other row" : job.predict;
    out.report["prediction"] = prediction_json(c);
    out.text += prediction_text(c);
    if (!job.outdir.empty()) {
      write_file_atomic(std::filesystem::path(job.outdir) / "prediction.json", prediction_json(c).dump(2) + "\n");
      out.files.push_back((std::filesystem::path(job.outdir) / "prediction.json").string());
    }
  }
  return out;
}

}  // namespace ofl
