// The model description of `oralfluor diagnose` (model.json) and the job's parameters.
// See docs/diagnose.md for the file format; every error names the file and JSON path.
#pragma once
#include <filesystem>
#include <optional>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/diagnose/camera/camera_model.h"
#include "renderer/diagnose/selection/cross_validation.h"
#include "renderer/diagnose/spectra/forward_model.h"
#include "renderer/diagnose/problem/measurement_set.h"

namespace ofl {

struct DiagnoseModelFile {
  std::string file;
  InputKind kind = InputKind::kSpectra;
  std::vector<RowFilter> select;    // rows of the index / patch table to use
  std::string file_column = "csv";  // spectra: index column naming each spectrum's file
  SelectionOptions selection;
  SpectraModel spectra;
  CameraModel camera;
};

DiagnoseModelFile load_diagnose_model(const std::filesystem::path& file);

// Everything one `oralfluor diagnose` run is asked to do (serialised into the JSON report).
struct DiagnoseJob {
  std::string input;                       // folder or CSV
  std::string model;                       // model.json
  std::string outdir;                      // plots, residual tables, report.json ("" = none)
  bool json = false;                       // print the JSON report on stdout
  std::vector<std::string> where;          // extra row filters "column=value"
  std::vector<std::string> groups;         // overrides the model's CV group columns
  std::optional<double> z;                 // overrides the selection's z
  std::optional<int> max_causes;
  std::string report_by;                   // overrides the model's report_by column
  std::string fit_on;                      // "column=a,b": select and fit on these rows only...
  std::string predict;                     // ...and predict these ("" = every other row)
  std::vector<std::string> shared_concentrations;  // overrides the model's shared_concentrations (spectra)
  // Library callers (the Python module): SelectionOptions::progress, called as causes are tried;
  // returning false stops the run (Interrupted). Not part of to_json.
  std::function<bool(int step, int64_t done, int64_t total)> progress;
  std::vector<std::string> tissue_per;             // overrides the model's tissue_per (spectra)
  nlohmann::json to_json() const;
};

// "column=value" (several values: "column=a|b") -> RowFilter; InputError naming `option` on a
// malformed string. `separators`: the characters between values ("|" for --where; --fit-on and
// --predict take "a,b" too).
RowFilter parse_where(const std::string& s, const std::string& option = "--where", const std::string& separators = "|");

}  // namespace ofl
