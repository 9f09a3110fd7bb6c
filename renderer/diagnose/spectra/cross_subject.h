// Fit on some subjects, predict others (`diagnose --fit-on subject=B --predict subject=Z`): the
// causes selected and their global parameters fitted on the first set are fixed, and only each
// predicted spectrum's own amplitudes (fluorophore concentrations, leak) are fitted, exactly as a
// held-out group is predicted in cross-validation. Reported per subject, site and excitation:
// RMSE in units of the spectrum's mean (as everywhere in diagnose) and with each spectrum
// normalised to 1 at 520 nm (as published fits of these data are), over the whole fit range and
// over 500-700 nm.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/diagnose/selection/cross_validation.h"
#include "renderer/diagnose/spectra/forward_model.h"

namespace ofl {

struct PredictionRow {
  std::string subject, site, light;
  int spectra = 0;
  double rmse_mean_baseline = 0, rmse_mean_extended = 0;  // units of the spectrum's mean
  double rmse_520_baseline = 0, rmse_520_extended = 0;    // spectra normalised to 1 at 520 nm
  double rmse_520_500_700_extended = 0;                   // the same over 500-700 nm only
};

struct CrossSubjectPrediction {
  std::string fit_on, predict;   // the row filters, as given
  int fit_spectra = 0, predicted_spectra = 0;
  std::vector<PredictionRow> rows;  // one per subject/site/light of the predicted set, then "all"
};

// `fitted` is the diagnosis of `fit_problem`; `target` holds the spectra to predict (same model).
CrossSubjectPrediction predict_other_subjects(const SpectraProblem& fit_problem, const Diagnosis& fitted,
                                              const SpectraProblem& target);

nlohmann::json prediction_json(const CrossSubjectPrediction& c);
std::string prediction_text(const CrossSubjectPrediction& c);

}  // namespace ofl
