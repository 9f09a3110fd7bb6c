// The camera forward model of `oralfluor diagnose`: the camera validation of predicted raw RGB
// against measured raw RGB for patches whose radiance spectra were measured (T' = S R).
// Linear sensor (EMVA 1288): mean signal of channel c for patch i
//   v_ic = g * exposure_i * sum_l L_i(l) T(l) QE_c(l) l dl        (photons ~ energy x wavelength)
// with g one exposure/conversion gain shared by all patches (the baseline's only parameter) and T
// the filters in front of the sensor (IR cut, emission long-pass). The causes of
// model_extensions.h bend this: per-channel gain, 3x3 crosstalk, offset, power-law
// nonlinearity, QE wavelength shift, NIR leak of the IR-cut filter. Residuals are in DN.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "renderer/diagnose/problem/diagnose_problem.h"
#include "renderer/diagnose/problem/measurement_set.h"
#include "renderer/diagnose/problem/model_extensions.h"
#include "renderer/spectral/spectra/spectrum.h"

namespace ofl {

struct CameraModel {
  std::array<Spectrum, 3> qe;        // R, G, B quantum efficiency (relative is fine)
  std::vector<Spectrum> filters;     // transmittances in front of the sensor
  double black_level = 0;            // DN subtracted from the measured means
  double nir_cut_nm = 0;             // NIR leak applies beyond this; 0: where the filters fall below 5 %
  double grid_step_nm = 4;
  CameraCandidateOptions candidates;
};

class CameraProblem : public DiagnoseProblem {
 public:
  CameraProblem(CameraPatchSet data, CameraModel model);

  std::string kind() const override { return "camera"; }
  std::string rmse_units() const override { return "DN (raw digital numbers after the black level)"; }
  int num_items() const override { return static_cast<int>(data_.patches.size()); }
  std::string item_label(int i) const override;
  std::string condition(int i, const std::string& column) const override;
  std::vector<double> abscissa(int) const override { return {0, 1, 2}; }
  std::vector<ParamSpec> baseline_params() const override;
  const std::vector<CandidateSpec>& candidates() const override { return candidates_; }
  std::vector<ItemFit> evaluate(const ModelState& state, const std::vector<int>& items) const override;
  Eigen::VectorXd measured(int i) const override { return y_[i]; }
  double fallback_noise_variance() const override;
  double centred_sum_of_squares(int i) const override;
  std::string plain_words(const CandidateSpec& c, const std::vector<double>& theta, const std::vector<double>& unc,
                          const std::vector<DerivedParam>& derived) const override;

  // Predicted means of every patch under `state` (for synthesising data).
  std::vector<std::array<double, 3>> predict(const ModelState& state) const;
  double nir_cut_nm() const { return nir_cut_; }
  const CameraPatchSet& data() const { return data_; }

 private:
  std::array<double, 3> predict_one(int i, const ModelState& s, const std::vector<std::array<double, 3>>& S) const;
  std::vector<std::array<double, 3>> sensor_signals(const ModelState& s) const;

  CameraPatchSet data_;
  CameraModel model_;
  WavelengthGrid grid_;
  std::vector<std::vector<double>> radiance_;  // per patch on the grid
  std::vector<double> filters_;                // product of the filters on the grid
  std::vector<Eigen::VectorXd> y_;
  std::vector<CandidateSpec> candidates_;
  double nir_cut_ = 0;
  double norm_ = 1;   // makes the baseline gain about 1
  double s_ref_ = 1;  // reference signal of the power law
};

}  // namespace ofl
