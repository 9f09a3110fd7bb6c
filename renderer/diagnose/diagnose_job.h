// One `oralfluor diagnose` run as a library call (the CLI and the Python module share it): reads
// the model and the measurements, fits, selects causes, writes the report files when asked, and
// returns the JSON report and the text summary.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/diagnose/diagnose_model.h"

namespace ofl {

struct DiagnoseOutcome {
  nlohmann::json report;            // what --json prints (report.json)
  std::string text;                 // what the command prints without --json
  std::vector<std::string> files;   // written into job.outdir (empty when no outdir)
};

DiagnoseOutcome run_diagnose_job(const DiagnoseJob& job);

// --fit-on / --predict: the selected rows split into those the causes are selected and fitted on
// and those predicted with the fitted global parameters fixed (cross_subject.h). Errors name the
// option: a malformed filter, a column the index lacks, a filter that takes no row, nothing left
// to predict, and rows asked to be predicted that are also fitted (an in-sample fit presented as
// a prediction of other subjects).
struct FitAndPredict {
  SpectraSet fit, predict;
};
FitAndPredict split_fit_and_predict(SpectraSet selected, const DiagnoseJob& job);

}  // namespace ofl
