// The common shape of a diagnosis problem, so that fitting, cross-validation and cause selection
// are written once for spectroradiometer spectra and for camera RGB patches.
//
// A problem has items (one measured spectrum, or one camera patch), each with a residual vector
// (measured - predicted, in the problem's RMSE units) under a model state. A model state is the
// baseline plus any number of active causes; each cause is a candidate extension with global
// parameters (shared by all items: a wavelength shift, a blood layer, a crosstalk matrix) and
// possibly local ones (per-item amplitudes, e.g. an extra fluorophore's concentration), which the
// problem fits itself inside `evaluate` (non-negative least squares). Global parameters are what
// cross-validation carries from training groups to held-out groups.
#pragma once
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "renderer/plot/vector_plot.h"

namespace ofl {

struct Diagnosis;  // the outcome of cause selection (selection/cross_validation.h, a room above this one)

struct ParamSpec {
  std::string name;         // JSON key, e.g. "delta_nm"
  std::string unit;         // e.g. "nm"
  double init = 0;
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  double fd_step = 1e-3;    // finite-difference step for the Jacobian
  std::vector<double> starts;  // values tried before local refinement (empty: init only)
  // Index, within its cause, of the parameter whose start value this one takes (-1: its own
  // starts). A parameter copied per subject starts where the first subject's copy starts, so the
  // start grid stays the product over one subject's parameters.
  int tie_start = -1;
};

struct CandidateSpec {
  std::string id;           // unique: "blood_absorption", "extra_fluorophore:chlorophyll_a"
  std::string name;         // the cause's name in reports: "blood_absorption", "extra_fluorophore"
  std::string title;        // a few words: "blood absorption (oxy/deoxy hemoglobin)"
  std::vector<ParamSpec> params;  // global parameters
  int local_dofs = 0;       // amplitudes it adds to every item's local fit
  // Tried only while the candidate with this id is active ("" = always), e.g. the emission shift
  // of an extra fluorophore once that fluorophore is in the model.
  std::string requires_id;
  // The range within which an estimate is a credible physical explanation (a parameter or derived
  // quantity by name, e.g. "fraction" of stray light up to 0.1). An estimate outside it is reported
  // as implausible and the cause is not accepted.
  struct Plausible {
    std::string quantity;
    double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
    std::string why;
  };
  std::vector<Plausible> plausible;
  bool instrument = false;  // a property of the instrument, not of the tissue
  // Overrides SelectionOptions::min_effect_to_noise for this cause (NaN: the selection's value).
  double min_effect_to_noise = std::numeric_limits<double>::quiet_NaN();
};

struct ActiveCause {
  int candidate = -1;
  std::vector<double> theta;
};

struct ModelState {
  std::vector<double> base_theta;  // global parameters of the baseline (camera: exposure gain)
  std::vector<ActiveCause> causes;
  bool has(int candidate) const {
    for (auto& c : causes)
      if (c.candidate == candidate) return true;
    return false;
  }
};

// One item evaluated under a model state.
struct ItemFit {
  Eigen::VectorXd residual;    // measured - predicted (problem units)
  Eigen::VectorXd measured;    // in the same units
  Eigen::VectorXd predicted;
  int local_dofs = 0;          // local amplitudes actually used (positive NNLS coefficients)
  // Named per-item quantities the problem derives for reporting, e.g. "fraction:FAD" (share of the
  // predicted signal) or "leak_od".
  std::map<std::string, double> locals;
};

// A part of the report that one kind of problem adds after the report every problem has (spectra:
// the unknown-band finder's estimate). The job puts `json` under `key` in the JSON report, appends
// `text` to the text summary and, when it writes files, draws `figure` as <figure_name>.svg and
// <figure_name>.png in the output folder; sections come in the order the problem gives them.
struct ReportSection {
  std::string key;                   // e.g. "unknown_band_estimate"
  nlohmann::json json;
  std::string text;                  // appended as it is ("" adds nothing)
  std::string figure_name;           // file name without extension, e.g. "unknown_band"
  std::optional<VectorPlot> figure;  // none: no figure files
};

// A reported quantity of a cause that is derived from the local fits rather than being a global
// parameter (e.g. the mean share of an extra fluorophore).
struct DerivedParam {
  std::string name, unit;
  double value = 0, uncertainty = 0;
};

class DiagnoseProblem {
 public:
  virtual ~DiagnoseProblem() = default;
  virtual std::string kind() const = 0;            // "spectra" or "camera"
  virtual std::string rmse_units() const = 0;      // what one unit of residual is
  virtual int num_items() const = 0;
  virtual std::string item_label(int i) const = 0;
  // The item's value in a condition column ("subject", "date", ...); "" when absent.
  virtual std::string condition(int i, const std::string& column) const = 0;
  // Abscissa of the residual vector (wavelengths in nm, or 0,1,2 for R,G,B).
  virtual std::vector<double> abscissa(int i) const = 0;
  virtual std::vector<ParamSpec> baseline_params() const = 0;
  virtual const std::vector<CandidateSpec>& candidates() const = 0;
  // Evaluates `items` under `state` (local amplitudes fitted per item). Must be thread safe.
  virtual std::vector<ItemFit> evaluate(const ModelState& state, const std::vector<int>& items) const = 0;
  // The measured values of item i in residual units (for the noise floor from replicates).
  virtual Eigen::VectorXd measured(int i) const = 0;
  // Noise variance per residual element from the data alone, for when there are no replicates
  // (spectra: high-frequency scatter; camera: patch standard deviations). <0 when unknown.
  virtual double fallback_noise_variance() const { return -1; }
  // Sum of squares of item i's measured values about the reference used for "variance explained".
  virtual double centred_sum_of_squares(int i) const = 0;
  // Reported quantities derived from the local fits of a cause (may be empty).
  virtual std::vector<DerivedParam> derived_params(const CandidateSpec& c, const std::vector<ItemFit>& fits,
                                                   const std::vector<int>& items) const {
    return {};
  }
  // Global parameters that `fitted_items` do not constrain (a per-subject tissue parameter of a
  // subject outside them) set from those they do; called after every fit on a subset of the
  // items, so that a held-out subject is predicted from the others.
  virtual void fill_unfitted(ModelState& state, const std::vector<int>& fitted_items) const {}
  // The cause in plain words with its estimates, e.g. "blood absorbs the emission: ...".
  virtual std::string plain_words(const CandidateSpec& c, const std::vector<double>& theta,
                                  const std::vector<double>& theta_uncertainty,
                                  const std::vector<DerivedParam>& derived) const = 0;
  // The report's sections that only this kind of problem has (ReportSection above), computed
  // from the finished diagnosis; the job adds each to the JSON report, the text summary and the
  // files, so it needs to know no kind of problem. Empty by default.
  virtual std::vector<ReportSection> report_sections(const Diagnosis& d) const { return {}; }
};

}  // namespace ofl
