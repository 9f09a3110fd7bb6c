// What `oralfluor diagnose` tells its user: the JSON report (--json, report.json), the text
// summary, the residual table (residuals.csv) and the SVG plots of the held-out residuals, fits
// and gains.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/diagnose/selection/cross_validation.h"
#include "renderer/diagnose/problem/diagnose_problem.h"

namespace ofl {

struct ReportContext {
  nlohmann::json job;               // DiagnoseJob::to_json()
  std::string input, model_file;
  std::vector<std::string> notes;   // data warnings from reading
  nlohmann::json model_options = nlohmann::json::object();  // e.g. blood_excitation_path_factor
};

nlohmann::json diagnosis_json(const DiagnoseProblem& p, const Diagnosis& d, const ReportContext& ctx);
std::string diagnosis_text(const DiagnoseProblem& p, const Diagnosis& d, const ReportContext& ctx);
// Writes report.json, residuals.csv and the SVG plots into `dir` (created); returns the files.
std::vector<std::string> write_diagnosis_files(const DiagnoseProblem& p, const Diagnosis& d, const ReportContext& ctx,
                                               const std::filesystem::path& dir);

}  // namespace ofl
