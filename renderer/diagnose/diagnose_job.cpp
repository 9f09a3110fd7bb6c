#include "renderer/diagnose/diagnose_job.h"

#include <algorithm>
#include <memory>
#include <optional>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/atomic_file.h"
#include "renderer/core/process/progress.h"
#include "renderer/diagnose/camera/camera_model.h"
#include "renderer/diagnose/spectra/cross_subject.h"
#include "renderer/diagnose/report/diagnose_report.h"
#include "renderer/diagnose/spectra/forward_model.h"

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

// "subject=B" for a row filter (values joined by commas, as --fit-on takes them).
std::string filter_text(const RowFilter& f) {
  std::string v;
  for (auto& x : f.values) v += (v.empty() ? "" : ",") + x;
  return f.column + "=" + v;
}

bool row_matches(const MeasuredSpectrum& s, const RowFilter& f) {
  auto it = s.conditions.find(f.column);
  const std::string cell = it == s.conditions.end() ? std::string() : it->second;
  for (auto& v : f.values)
    if (cell_matches(cell, v)) return true;
  return false;
}

// The distinct values of a column among the selected rows, for messages ("B, Z").
std::string values_of(const SpectraSet& set, const std::string& column) {
  std::vector<std::string> seen;
  for (auto& s : set.spectra) {
    auto it = s.conditions.find(column);
    std::string v = it == s.conditions.end() ? std::string() : it->second;
    if (std::find(seen.begin(), seen.end(), v) == seen.end()) seen.push_back(v);
  }
  std::string out;
  for (size_t k = 0; k < seen.size() && k < 12; ++k) out += (k ? ", " : "") + (seen[k].empty() ? std::string("(empty)") : seen[k]);
  if (seen.size() > 12) out += ", ...";
  return out;
}

// The rows of `all` that `option`'s filter takes; an error naming the option when its column is
// not in the index or it takes none of the selected rows.
std::vector<size_t> rows_taken(const SpectraSet& all, const RowFilter& f, const std::string& option) {
  bool has_column = false;
  for (auto& s : all.spectra) has_column = has_column || s.conditions.count(f.column) > 0;
  if (!has_column) throw InputError("command line", option, "column \"" + f.column + "\" is not in " + all.index_file);
  std::vector<size_t> rows;
  for (size_t i = 0; i < all.spectra.size(); ++i)
    if (row_matches(all.spectra[i], f)) rows.push_back(i);
  if (rows.empty())
    throw InputError("command line", option,
                     filter_text(f) + " takes none of the " + std::to_string(all.spectra.size()) + " selected rows (" + f.column +
                         " there: " + values_of(all, f.column) + ")");
  return rows;
}

}  // namespace

FitAndPredict split_fit_and_predict(SpectraSet all, const DiagnoseJob& job) {
  const RowFilter fit = parse_where(job.fit_on, "--fit-on", ",|");
  std::vector<size_t> fit_rows = rows_taken(all, fit, "--fit-on");
  std::vector<char> in_fit(all.spectra.size(), 0);
  for (size_t i : fit_rows) in_fit[i] = 1;
  std::vector<size_t> pred_rows;
  if (!job.predict.empty()) {
    const RowFilter pred = parse_where(job.predict, "--predict", ",|");
    pred_rows = rows_taken(all, pred, "--predict");
    // A prediction of rows the causes were fitted on is an in-sample fit, not a prediction of others.
    std::vector<size_t> both;
    for (size_t i : pred_rows)
      if (in_fit[i]) both.push_back(i);
    if (!both.empty())
      throw InputError("command line", "--predict",
                       std::to_string(both.size()) + " of the " + std::to_string(pred_rows.size()) + " rows of " + filter_text(pred) +
                           " are also fitted by --fit-on " + filter_text(fit) + " (e.g. " + all.spectra[both[0]].label +
                           "): predicting them is no prediction of other rows; choose rows --fit-on does not take");
  } else {
    for (size_t i = 0; i < all.spectra.size(); ++i)
      if (!in_fit[i]) pred_rows.push_back(i);
    if (pred_rows.empty())
      throw InputError("command line", "--fit-on", filter_text(fit) + " takes every selected row: nothing is left to predict");
  }
  FitAndPredict out;
  out.fit.index_file = out.predict.index_file = all.index_file;
  out.fit.notes = all.notes;
  for (size_t i : fit_rows) out.fit.spectra.push_back(all.spectra[i]);
  for (size_t i : pred_rows) out.predict.spectra.push_back(std::move(all.spectra[i]));
  return out;
}

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
  sel.progress = job.progress;
  if (!job.tissue_per.empty()) m.spectra.tissue_per = job.tissue_per;

  std::unique_ptr<DiagnoseProblem> problem;
  ReportContext ctx;
  ctx.job = job.to_json();
  ctx.input = job.input;
  ctx.model_file = job.model;
  std::unique_ptr<SpectraProblem> target;  // --fit-on: the spectra to predict
  const SpectraProblem* fitted = nullptr;  // --fit-on: `problem`, the spectra the causes are fitted on
  if (!job.fit_on.empty() && kind != InputKind::kSpectra)
    throw InputError("command line", "--fit-on", "fitting on some rows and predicting others is for spectra");
  if (!job.predict.empty() && job.fit_on.empty()) throw InputError("command line", "--predict", "needs --fit-on");
  std::optional<SpectraSet> fit_set;
  if (kind == InputKind::kSpectra && !job.fit_on.empty()) {
    FitAndPredict split = split_fit_and_predict(read_spectra_index(job.input, m.file_column, select), job);
    target = spectra_problem(std::move(split.predict), m.spectra, job.model);
    fit_set = std::move(split.fit);
  }
  if (kind == InputKind::kSpectra) {
    SpectraSet data = fit_set ? std::move(*fit_set) : read_spectra_index(job.input, m.file_column, select);
    ctx.notes = data.notes;
    ctx.model_options = {{"blood_excitation_path_factor", m.spectra.candidates.blood_excitation_path_factor},
                         {"fit_range_nm", {m.spectra.fit_min_nm, m.spectra.fit_max_nm}},
                         {"fluorophores", m.spectra.fluorophores},
                         {"shared_concentrations", m.spectra.shared_by},
                         {"tissue_per", m.spectra.tissue_per}};
    std::unique_ptr<SpectraProblem> sp = spectra_problem(std::move(data), std::move(m.spectra), job.model);
    if (target) fitted = sp.get();
    problem = std::move(sp);
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
  for (ReportSection& s : problem->report_sections(d)) {
    out.report[s.key] = std::move(s.json);
    out.text += s.text;
    if (s.figure && !job.outdir.empty()) {
      auto stem = std::filesystem::path(job.outdir) / s.figure_name;
      s.figure->write_svg_and_png(stem);
      out.files.push_back(stem.string() + ".svg");
      out.files.push_back(stem.string() + ".png");
    }
  }
  if (target) {
    CrossSubjectPrediction c = predict_other_subjects(*fitted, d, *target);
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
