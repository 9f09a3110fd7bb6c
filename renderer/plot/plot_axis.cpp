#include "renderer/plot/plot_axis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ofl {

double nice_tick_step(double range, int target) {
  if (!(range > 0) || !std::isfinite(range)) return 1.0;
  const double raw = range / std::max(1, target);
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0})
    if (m * decade >= raw) return m * decade;
  return 10 * decade;
}

std::vector<double> axis_ticks(double lo, double hi, double step) {
  std::vector<double> t;
  if (!(step > 0) || !(hi >= lo)) return t;
  const double tol = 1e-9 * step;
  for (double k = std::ceil((lo - tol) / step); k * step <= hi + tol; k += 1) t.push_back(k * step);
  return t;
}

std::string tick_label(double v, double step) {
  if (std::fabs(v) < step * 1e-6) v = 0;  // no "-0.0" or 1e-17
  char b[32];
  const double a = std::fabs(v);
  if (a != 0 && (a < 1e-3 || a >= 1e5)) {
    std::snprintf(b, sizeof b, "%.2g", v);
  } else {
    int dec = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
    const double scaled = step * std::pow(10.0, dec);
    if (std::fabs(scaled - std::round(scaled)) > 1e-6) ++dec;  // 2.5 steps need one more
    std::snprintf(b, sizeof b, "%.*f", std::min(dec, 6), v);
  }
  return b;
}

}  // namespace ofl
