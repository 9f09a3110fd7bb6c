#include "renderer/spectral/spectra/optical_filter.h"

#include <cmath>

namespace ofl {
namespace {
// Logistic step from 0 to 1 centred on `edge` whose 10%-90% rise takes `width` nm.
double rising(double nm, double edge, double width) {
  double s = std::max(width, 1e-6) / (2.0 * std::log(9.0));
  return 1.0 / (1.0 + std::exp(-(nm - edge) / s));
}
}  // namespace

double OpticalFilter::shift_factor(double aoi) const {
  if (!interference) return 1.0;
  double s = std::sin(aoi) / n_eff;
  return std::sqrt(std::max(0.0, 1.0 - s * s));
}

double OpticalFilter::transmittance(double nm, double aoi) const {
  double f = shift_factor(aoi);
  if (kind == Kind::kMeasured) return measured.eval(nm / f);
  double tmin = std::pow(10.0, -od);
  double e1 = edge_nm * f, e2 = edge2_nm * f;
  double pass = 0;
  switch (kind) {
    case Kind::kLongpass: pass = rising(nm, e1, width_nm); break;
    case Kind::kShortpass: pass = 1.0 - rising(nm, e1, width_nm); break;
    case Kind::kBandpass: pass = rising(nm, e1, width_nm) * (1.0 - rising(nm, e2, width_nm)); break;
    case Kind::kMeasured: break;
  }
  return tmin + (peak - tmin) * pass;
}

Spectrum OpticalFilter::at_angle(double aoi) const {
  OpticalFilter copy = *this;
  Spectrum s;
  s.eval = [copy, aoi](double nm) { return copy.transmittance(nm, aoi); };
  if (kind == Kind::kMeasured) {
    double f = shift_factor(aoi);
    for (double k : measured.kinks) s.kinks.push_back(k * f);
  } else {
    s.kinks = {};
  }
  s.description = name.empty() ? "filter" : name;
  return s;
}

}  // namespace ofl
