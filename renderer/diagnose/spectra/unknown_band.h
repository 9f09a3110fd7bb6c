// The unknown-band finder of `diagnose`: when the residual keeps structure that no library cause
// explains, estimate the missing component's spectrum from the data themselves by multivariate
// curve resolution with non-negativity (MCR-ALS): every spectrum is modelled as the current
// model's columns plus a_i s(lambda) with one shared shape s >= 0 and amplitudes a_i >= 0; the
// amplitudes (with the model's own amplitudes) are solved by NNLS per spectrum and the shape by
// least squares over all spectra, clipped at zero, alternately. Started from the positive part
// of the mean residual. The shape is what the instrument records (after the filters and any
// blood in the model); its peak and width are reported with the library spectra it resembles.
// The held-out gain is that of the `unknown_band` candidate (a parametric band selected like any
// cause); this estimate is its free-form picture.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "renderer/diagnose/spectra/forward_model.h"

namespace ofl {

struct UnknownBandEstimate {
  bool found = false;
  std::vector<double> nm, shape;  // peak-normalised, on the first spectrum's fit wavelengths
  double peak_nm = 0, fwhm_nm = 0;
  double mean_fraction = 0;       // mean share of the predicted signal
  double rss_before = 0, rss_after = 0;  // in-sample sums of squares without/with the component
  std::vector<std::pair<std::string, double>> closest;  // library emission spectra by correlation
  int iterations = 0;
};

// `state`: the model without the unknown band (its columns are kept, their amplitudes refitted).
UnknownBandEstimate estimate_unknown_band(const SpectraProblem& p, const ModelState& state, int iterations = 60);

}  // namespace ofl

#include <nlohmann/json.hpp>

#include "renderer/diagnose/selection/cross_validation.h"
#include "renderer/plot/vector_plot.h"

namespace ofl {

// After a diagnosis of spectra: the free-form estimate of the accepted unknown band (fitted on
// the final model without it), or, when no band was accepted but the extended model still misses
// by more than twice the noise floor, of what is left (reported as residual structure, with no
// held-out claim). `found` is false when neither applies.
struct UnknownBandReport {
  UnknownBandEstimate estimate;
  bool accepted = false;  // the unknown_band cause was accepted (its held-out gain is in the report)
};
UnknownBandReport unknown_band_report(const SpectraProblem& p, const Diagnosis& d);
nlohmann::json unknown_band_json(const UnknownBandReport& r);
std::string unknown_band_text(const UnknownBandReport& r);
VectorPlot unknown_band_plot(const UnknownBandReport& r);

}  // namespace ofl
