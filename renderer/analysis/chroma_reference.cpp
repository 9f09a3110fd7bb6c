#include "renderer/analysis/chroma_reference.h"

#include <algorithm>
#include <cmath>

#include "renderer/camera/sensor/expected_signal.h"
#include "renderer/analysis/chromaticity.h"

namespace ofl {

ReferenceSetup make_reference_setup(const CameraDescription& cam, const Spectrum& led, const Spectrum& refl,
                                    const ReferenceOptions& o) {
  double lo = o.camera_lo_nm > 0 ? o.camera_lo_nm : 1e300, hi = o.camera_hi_nm > 0 ? o.camera_hi_nm : 0;
  if (led.kinks.size() >= 2) {
    lo = std::min(lo, led.kinks.front());
    hi = std::max(hi, led.kinks.back());
  }
  for (int c = 0; c < 3; ++c)
    if (o.camera_lo_nm <= 0 && cam.sensor.qe[c].kinks.size() >= 2) {
      lo = std::min(lo, cam.sensor.qe[c].kinks.front());
      hi = std::max(hi, cam.sensor.qe[c].kinks.back());
    }
  if (!(hi > lo)) {  // nothing tabulated anywhere: the visible range
    lo = 380;
    hi = 780;
  }
  double step = o.step_nm;
  double a = std::ceil(lo / step - 1e-9) * step;
  double b = a + std::floor((hi - a) / step + 1e-9) * step;
  if (!(b > a)) b = a + step;
  ReferenceSetup s;
  s.grid = WavelengthGrid{a, b, step};
  std::vector<double> e = tabulate(led, s.grid);
  s.reflectance = tabulate(refl, s.grid);
  s.excitation_q.resize(e.size());
  for (int i = 0; i < s.grid.size(); ++i) s.excitation_q[i] = std::max(0.0, e[i]) * s.grid.wavelength(i);
  for (int c = 0; c < 3; ++c) {
    Spectrum q{[&cam, c, o](double nm) { return system_qe(cam, c, nm, o.aoi_front_rad, o.aoi_sensor_rad); }, {}, "qe"};
    q.kinks = cam.sensor.qe[c].kinks;
    s.response[c] = tabulate(q, s.grid);
    if (o.camera_lo_nm > 0 && o.camera_hi_nm > 0)
      for (int i = 0; i < s.grid.size(); ++i) {
        double nm = s.grid.wavelength(i);
        if (nm < o.camera_lo_nm || nm > o.camera_hi_nm) s.response[c][i] = 0.0;
      }
  }
  return s;
}

std::array<double, 3> reference_signal(const ReferenceSetup& s, const GridEem* eem, double c) {
  int n = s.grid.size();
  std::vector<double> L(n);
  for (int i = 0; i < n; ++i) L[i] = s.reflectance[i] * s.excitation_q[i];
  if (eem && c != 0) {
    std::vector<double> f = eem->apply(s.excitation_q);
    for (int i = 0; i < n; ++i) L[i] += c * f[i];
  }
  std::array<double, 3> out = {0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < n; ++i) out[k] += L[i] * s.response[k][i] * s.grid.step_nm / 3.14159265358979323846;
  return out;
}

std::array<double, 2> reference_rg(const ReferenceSetup& s, const GridEem* eem, double c) {
  auto S = reference_signal(s, eem, c);
  return rg_chromaticity(S[0], S[1], S[2]);
}

nlohmann::json ReferenceLine::to_json() const {
  return {{"fluorophore", fluorophore}, {"concentration", concentration}, {"rg", rg},
          {"pure_rg", pure_rg},        {"balance_concentration", balance_concentration}, {"visible", visible}};
}

ReferenceLine reference_line(const ReferenceSetup& s, const std::string& name, const GridEem& eem,
                             const std::vector<double>& conc) {
  ReferenceLine line;
  line.fluorophore = name;
  auto refl = reference_signal(s, nullptr, 0.0);
  auto with1 = reference_signal(s, &eem, 1.0);
  double sr = refl[0] + refl[1] + refl[2];
  double sf = (with1[0] - refl[0]) + (with1[1] - refl[1]) + (with1[2] - refl[2]);
  line.visible = sf > 1e-12 * std::max(sr, 1e-300);
  line.pure_rg = line.visible ? rg_chromaticity(with1[0] - refl[0], with1[1] - refl[1], with1[2] - refl[2])
                              : reference_rg(s, nullptr, 0.0);
  line.balance_concentration = line.visible ? sr / sf : 0.0;
  if (!conc.empty()) {
    line.concentration = conc;
    if (line.concentration.front() != 0.0) line.concentration.insert(line.concentration.begin(), 0.0);
  } else {
    line.concentration.push_back(0.0);
    if (line.visible) {
      constexpr int kSteps = 17;
      for (int i = 0; i < kSteps; ++i)
        line.concentration.push_back(line.balance_concentration * std::pow(10.0, -2.0 + 4.0 * i / (kSteps - 1)));
    }
  }
  for (double c : line.concentration) line.rg.push_back(reference_rg(s, &eem, c));
  return line;
}

}  // namespace ofl
