#include "renderer/diagnose/spectra/cross_subject.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>

#include "renderer/core/errors/error.h"

namespace ofl {

namespace {

// The value of the target's parameter `name` from the fitted cause's parameters: the same name,
// or for a per-tissue copy ("oxy_uM_cm@Z") of a tissue the fit did not see, the mean of the
// fitted tissues' copies (as a held-out subject is predicted in cross-validation).
bool carried_value(const std::string& name, const std::vector<ParamSpec>& from, const std::vector<double>& theta, double& v) {
  for (size_t j = 0; j < from.size(); ++j)
    if (from[j].name == name) { v = theta[j]; return true; }
  const auto at = name.find('@');
  if (at == std::string::npos) return false;
  const std::string base = name.substr(0, at + 1);
  double m = 0;
  int n = 0;
  for (size_t j = 0; j < from.size(); ++j)
    if (from[j].name.compare(0, base.size(), base) == 0) { m += theta[j]; ++n; }
  if (n == 0) return false;
  v = m / n;
  return true;
}

// The fitted state with its causes re-indexed into the target's candidate list (by id) and its
// parameters carried by name.
ModelState state_for(const SpectraProblem& from, const ModelState& s, const SpectraProblem& to) {
  ModelState out = s;
  for (auto& c : out.causes) {
    const std::string& id = from.candidates()[c.candidate].id;
    int k = -1;
    for (size_t j = 0; j < to.candidates().size(); ++j)
      if (to.candidates()[j].id == id) k = static_cast<int>(j);
    if (k < 0) throw InputError("--predict", id, "the predicted spectra's model has no candidate of this id (other fit range?)");
    const auto& tp = to.candidates()[k].params;
    std::vector<double> theta(tp.size());
    for (size_t j = 0; j < tp.size(); ++j)
      if (!carried_value(tp[j].name, from.candidates()[c.candidate].params, c.theta, theta[j]))
        throw InputError("--predict", id, "the predicted spectra cover another wavelength range, so this cause has other parameters");
    c.candidate = k;
    c.theta = std::move(theta);
  }
  return out;
}

// Measured value at `nm` (linear interpolation on the item's abscissa), in residual units.
double value_at(const std::vector<double>& x, const Eigen::VectorXd& y, double nm) {
  for (size_t k = 1; k < x.size(); ++k)
    if (x[k] >= nm) {
      double t = (nm - x[k - 1]) / (x[k] - x[k - 1]);
      return y[static_cast<Eigen::Index>(k - 1)] * (1 - t) + y[static_cast<Eigen::Index>(k)] * t;
    }
  return NAN;
}

struct Sums {
  double mean_b = 0, mean_e = 0, n520_b = 0, n520_e = 0, n520_e_band = 0;
  long n = 0, n_band = 0;
  int spectra = 0;
  void add(const std::vector<double>& x, const ItemFit& b, const ItemFit& e) {
    double y520 = value_at(x, e.measured, 520);
    double k = std::isfinite(y520) && y520 > 0 ? 1.0 / y520 : NAN;
    for (Eigen::Index i = 0; i < e.residual.size(); ++i) {
      mean_b += b.residual[i] * b.residual[i];
      mean_e += e.residual[i] * e.residual[i];
      n520_b += b.residual[i] * b.residual[i] * k * k;
      n520_e += e.residual[i] * e.residual[i] * k * k;
      if (x[static_cast<size_t>(i)] >= 500 && x[static_cast<size_t>(i)] <= 700) {
        n520_e_band += e.residual[i] * e.residual[i] * k * k;
        ++n_band;
      }
      ++n;
    }
    ++spectra;
  }
  PredictionRow row(const std::string& sub, const std::string& site, const std::string& light) const {
    PredictionRow r{sub, site, light, spectra};
    auto rt = [](double s, long m) { return m ? std::sqrt(s / m) : 0.0; };
    r.rmse_mean_baseline = rt(mean_b, n);
    r.rmse_mean_extended = rt(mean_e, n);
    r.rmse_520_baseline = rt(n520_b, n);
    r.rmse_520_extended = rt(n520_e, n);
    r.rmse_520_500_700_extended = rt(n520_e_band, n_band);
    return r;
  }
};

}  // namespace

CrossSubjectPrediction predict_other_subjects(const SpectraProblem& fit_problem, const Diagnosis& fitted,
                                              const SpectraProblem& target) {
  CrossSubjectPrediction out;
  out.fit_spectra = fit_problem.num_items();
  out.predicted_spectra = target.num_items();
  std::vector<int> all(target.num_items());
  for (int i = 0; i < target.num_items(); ++i) all[i] = i;
  auto base = target.evaluate(state_for(fit_problem, fitted.baseline_fit.state, target), all);
  auto ext = target.evaluate(state_for(fit_problem, fitted.final_fit.state, target), all);
  std::map<std::string, Sums> by;
  std::vector<std::string> order;
  Sums total;
  for (int i = 0; i < target.num_items(); ++i) {
    std::string key = target.condition(i, "subject") + "\t" + target.condition(i, "site") + "\t" + target.condition(i, "light_nm");
    if (!by.count(key)) order.push_back(key);
    auto x = target.abscissa(i);
    by[key].add(x, base[i], ext[i]);
    total.add(x, base[i], ext[i]);
  }
  for (auto& k : order) {
    auto a = k.find('\t'), b = k.find('\t', a + 1);
    out.rows.push_back(by[k].row(k.substr(0, a), k.substr(a + 1, b - a - 1), k.substr(b + 1)));
  }
  out.rows.push_back(total.row("all", "", ""));
  return out;
}

nlohmann::json prediction_json(const CrossSubjectPrediction& c) {
  nlohmann::json rows = nlohmann::json::array();
  for (auto& r : c.rows)
    rows.push_back({{"subject", r.subject}, {"site", r.site}, {"light_nm", r.light}, {"spectra", r.spectra},
                    {"rmse_mean_baseline", r.rmse_mean_baseline}, {"rmse_mean_extended", r.rmse_mean_extended},
                    {"rmse_520_baseline", r.rmse_520_baseline}, {"rmse_520_extended", r.rmse_520_extended},
                    {"rmse_520_500_700_extended", r.rmse_520_500_700_extended}});
  return {{"fit_on", c.fit_on}, {"predict", c.predict}, {"fit_spectra", c.fit_spectra},
          {"predicted_spectra", c.predicted_spectra}, {"rows", rows}};
}

std::string prediction_text(const CrossSubjectPrediction& c) {
  std::ostringstream o;
  o << "\nprediction of other subjects (fitted on " << c.fit_on << ", " << c.fit_spectra << " spectra; predicting " << c.predict
    << ", " << c.predicted_spectra << " spectra; global parameters fixed, amplitudes refitted):\n";
  o << "  subject  site     light  spectra  RMSE/mean baseline -> extended   RMSE@520 baseline -> extended  (500-700 nm)\n";
  for (auto& r : c.rows) {
    char b[256];
    std::snprintf(b, sizeof b, "  %-8s %-8s %-6s %7d  %8.4f -> %8.4f             %8.4f -> %8.4f       (%.4f)\n", r.subject.c_str(),
                  r.site.c_str(), r.light.c_str(), r.spectra, r.rmse_mean_baseline, r.rmse_mean_extended, r.rmse_520_baseline,
                  r.rmse_520_extended, r.rmse_520_500_700_extended);
    o << b;
  }
  return o.str();
}

}  // namespace ofl
