#include "materials/corrections/diagnosis_corrections.h"

#include <cmath>

#include "renderer/core/errors/error.h"
#include "renderer/spectral/spectra/sample_shapes.h"

namespace ofl {

namespace {
double need(const nlohmann::json& obj, const char* key, const std::string& cause) {
  if (!obj.is_object() || !obj.contains(key) || !obj[key].is_number())
    throw InputError("diagnose report", "/causes/" + cause + "/" + key, "missing number");
  return obj[key].get<double>();
}
double maybe(const nlohmann::json& obj, const char* key) {
  return obj.is_object() && obj.contains(key) && obj[key].is_number() ? obj[key].get<double>() : 0.0;
}
}  // namespace

TissueCorrections tissue_corrections_from_report(const nlohmann::json& report) {
  TissueCorrections c;
  if (!report.contains("causes") || !report["causes"].is_array())
    throw InputError("diagnose report", "/causes", "missing (not a report of oralfluor diagnose?)");
  double path_factor = 0;
  if (report.contains("model_options") && report["model_options"].is_object())
    path_factor = maybe(report["model_options"], "blood_excitation_path_factor");
  for (auto& cause : report["causes"]) {
    std::string name = cause.value("name", "");
    const auto& par = cause.contains("parameters") ? cause["parameters"] : nlohmann::json::object();
    const auto& unc = cause.contains("uncertainty") ? cause["uncertainty"] : nlohmann::json::object();
    if (name == "blood_absorption") {
      BloodAbsorber b;
      b.oxy_uM_cm = need(par, "oxy_uM_cm", name);
      b.deoxy_uM_cm = need(par, "deoxy_uM_cm", name);
      b.excitation_path_factor = path_factor;
      c.blood = b;
      c.blood_uncertainty.oxy_uM_cm = maybe(unc, "oxy_uM_cm");
      c.blood_uncertainty.deoxy_uM_cm = maybe(unc, "deoxy_uM_cm");
    } else if (name == "extra_fluorophore") {
      ExtraFluorophoreShare e;
      if (!par.contains("fluorophore") || !par["fluorophore"].is_string())
        throw InputError("diagnose report", "/causes/extra_fluorophore/fluorophore", "missing name");
      e.name = par["fluorophore"].get<std::string>();
      e.mean_fraction = need(par, "mean_fraction", name);
      e.uncertainty = maybe(unc, "mean_fraction");
      c.extra_fluorophores.push_back(e);
    } else if (name == "emission_broadening") {
      c.emission_broadening_fwhm_nm = need(par, "fwhm_nm", name);
    } else if (!name.empty() && !cause.value("instrument", true)) {
      // A tissue cause the surface material has no parameter for (a per-fluorophore emission
      // shift, width or second band, an unknown band): the caller warns that it is not rendered.
      c.unrendered_tissue_causes.push_back(cause.value("id", name));
    } else if (!name.empty()) {
      c.instrument_causes.push_back(name);
    }
  }
  return c;
}

std::vector<double> blood_optical_density_on_grid(const BloodAbsorber& b, const WavelengthGrid& grid) {
  return tabulate(blood_optical_density_spectrum(b), grid);
}

GridEem apply_tissue_corrections(const GridEem& eem, const TissueCorrections& c) {
  GridEem out = eem;
  const int n = eem.n();
  if (c.emission_broadening_fwhm_nm > 0) {
    std::vector<double> col(n);
    for (int ex = 0; ex < n; ++ex) {
      // Blurred as the diagnosis blurs an emission column: in energy units (photons x hc/em; the
      // constant drops out), then back to photons. What lands at or below the excitation
      // wavelength is dropped (Stokes), not renormalised, so that above the excitation the EEM is
      // exactly the fitted model and the photon albedo can only decrease.
      double before = 0;
      for (int em = 0; em < n; ++em) {
        col[em] = eem.at(em, ex) / eem.grid.wavelength(em);
        before += col[em];
      }
      if (before <= 0) continue;
      gaussian_blur(col, eem.grid.step_nm, c.emission_broadening_fwhm_nm);
      for (int em = 0; em < n; ++em) out.at(em, ex) = em <= ex ? 0.0 : col[em] * eem.grid.wavelength(em);
    }
  }
  if (c.blood) out = apply_blood_to_eem(out, *c.blood);
  return out;
}

}  // namespace ofl
