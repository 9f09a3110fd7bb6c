#include "renderer/spectral/chromophores/hemoglobin.h"

#include <cmath>

#include "renderer/core/files/asset_path.h"
#include "renderer/core/files/file_dependencies.h"

namespace ofl {

const HemoglobinTables& hemoglobin_tables() {
  // Noted on every call (the tables are read once per process), so that every scene that uses
  // blood lists the same inputs (file_dependencies.h).
  if (recording_file_dependencies()) {
    note_file_dependency(asset_root() / "spectra/hemoglobin/oxyHemoglobin.csv");
    note_file_dependency(asset_root() / "spectra/hemoglobin/deoxyHemoglobin.csv");
  }
  static const HemoglobinTables t = [] {
    HemoglobinTables h;
    SpectrumCsvOptions o;
    o.outside = Outside::kClamp;
    h.oxy = read_spectrum_csv(asset_path("spectra/hemoglobin/oxyHemoglobin.csv"), o);
    h.deoxy = read_spectrum_csv(asset_path("spectra/hemoglobin/deoxyHemoglobin.csv"), o);
    return h;
  }();
  return t;
}

BloodAbsorber BloodAbsorber::whole_blood(double thickness_um, double saturation, double volume_fraction,
                                         double hemoglobin_g_per_L) {
  // 64 500 g/mol per hemoglobin tetramer (the molar basis of Prahl's table).
  double hb_uM = hemoglobin_g_per_L / 64500.0 * 1e6 * volume_fraction;
  double path_cm = thickness_um * 1e-4;
  BloodAbsorber b;
  b.oxy_uM_cm = hb_uM * path_cm * saturation;
  b.deoxy_uM_cm = hb_uM * path_cm * (1.0 - saturation);
  return b;
}

double blood_optical_density(const BloodAbsorber& b, double nm) {
  const auto& t = hemoglobin_tables();
  return 1e-6 * (b.oxy_uM_cm * t.oxy.eval(nm) + b.deoxy_uM_cm * t.deoxy.eval(nm));
}

Spectrum blood_optical_density_spectrum(const BloodAbsorber& b) {
  const auto& t = hemoglobin_tables();
  Spectrum s;
  s.eval = [b](double nm) { return blood_optical_density(b, nm); };
  s.kinks = t.oxy.nm;
  s.description = "blood optical density";
  return s;
}

double blood_transmittance(const BloodAbsorber& b, double nm) { return std::pow(10.0, -blood_optical_density(b, nm)); }

std::vector<double> blood_transmittance(const BloodAbsorber& b, const WavelengthGrid& grid) {
  Spectrum s;
  s.eval = [b](double nm) { return blood_transmittance(b, nm); };
  s.kinks = hemoglobin_tables().oxy.nm;
  s.description = "blood transmittance";
  return tabulate(s, grid);
}

GridEem apply_blood_to_eem(const GridEem& eem, const BloodAbsorber& b) {
  auto t = blood_transmittance(b, eem.grid);
  GridEem out = eem;
  int n = eem.n();
  std::vector<double> tex(n, 1.0);
  if (b.excitation_path_factor != 0)
    for (int i = 0; i < n; ++i) tex[i] = std::pow(t[i], b.excitation_path_factor);
  for (int em = 0; em < n; ++em)
    for (int ex = 0; ex < n; ++ex) out.at(em, ex) *= t[em] * tex[ex];
  return out;
}

std::vector<double> apply_blood_to_reflectance(const std::vector<double>& r, const WavelengthGrid& grid,
                                               const BloodAbsorber& b) {
  auto t = blood_transmittance(b, grid);
  std::vector<double> out(r.size());
  for (size_t i = 0; i < r.size(); ++i) out[i] = r[i] * t[i] * t[i];
  return out;
}

double whole_blood_mua_per_mm(double nm, double saturation, double hb_g_per_L) {
  const auto& t = hemoglobin_tables();
  double eps = saturation * t.oxy.eval(nm) + (1.0 - saturation) * t.deoxy.eval(nm);  // cm^-1 M^-1, base 10
  return std::log(10.0) * eps * (hb_g_per_L / 64500.0) / 10.0;
}

Spectrum tissue_blood_mua_spectrum(double volume_fraction, double saturation, double hb_g_per_L, double vessel_radius_um) {
  Spectrum s;
  s.eval = [=](double nm) {
    double mua_bl = whole_blood_mua_per_mm(nm, saturation, hb_g_per_L);
    double packing = 1.0;
    double x = 2.0 * mua_bl * vessel_radius_um * 1e-3;
    if (x > 1e-9) packing = (1.0 - std::exp(-x)) / x;
    return volume_fraction * mua_bl * packing;
  };
  s.kinks = hemoglobin_tables().oxy.nm;
  s.description = "blood absorption";
  return s;
}

}  // namespace ofl
