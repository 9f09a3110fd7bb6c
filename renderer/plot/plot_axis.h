// Axis ticks shared by every plot writer (diagnose charts, sweep report, chromaticity plot):
// a "nice" step (1, 2, 2.5 or 5 times a power of ten), the tick values it gives over a range,
// and tick labels with just enough decimals for the step.
#pragma once
#include <string>
#include <vector>

namespace ofl {

// Smallest nice step giving at most about `target` intervals over `range`; 1 for an empty range.
double nice_tick_step(double range, int target);

// Multiples of `step` within [lo, hi] (ends included up to rounding), computed as k * step so
// that long axes do not accumulate rounding error.
std::vector<double> axis_ticks(double lo, double hi, double step);

// `v` with the decimals `step` needs ("0.25", "10", "-0.5"); %.2g for very large or small values.
std::string tick_label(double v, double step);

}  // namespace ofl
