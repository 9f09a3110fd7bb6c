// Shapes of spectra sampled on a uniform wavelength grid: a Gaussian blur of a given FWHM and a
// shift by a fraction of the step. Used where a fitted or corrected spectrum is broadened or moved
// (diagnose's causes, a tissue material's corrections from a diagnosis report).
#pragma once
#include <vector>

namespace ofl {

// Operations on a spectrum sampled every `step_nm` (linear in the samples).
// Gaussian blur of full width at half maximum `fwhm_nm`; near the ends the kernel is renormalised
// over the samples it covers, so a constant stays constant.
void gaussian_blur(std::vector<double>& v, double step_nm, double fwhm_nm);
// v'(l) = v(l - delta): a feature at l0 moves to l0 + delta (cubic Catmull-Rom interpolation, which
// keeps a sharp edge sharp; ends clamped).
void shift_samples(std::vector<double>& v, double step_nm, double delta_nm);

}  // namespace ofl
