// The candidate causes `diagnose` can name, each a model extension with its own parameters, and
// the spectral operations they need.
//
// Spectra (spectroradiometer, fluorophore-only baseline):
//   blood_absorption     Beer-Lambert oxy/deoxy hemoglobin on the emission (optionally the
//                        excitation): global oxy_uM_cm, deoxy_uM_cm
//   extra_fluorophore:X  library fluorophore X missing from the baseline: one amplitude per spectrum
//   wavelength_shift     the instrument's wavelength scale is off: global delta_nm (everything the
//                        instrument sees moves: fluorescence, filter edge, leak)
//   emission_shift       every fluorophore's emission sits elsewhere than in the library (tissue vs
//                        solution): global delta_nm on the fluorescence only
//   emission_shift:X     fluorophore X's emission moved: delta_nm (bounded +-15 nm)
//   emission_width:X     fluorophore X's emission broader than the library's: Gaussian fwhm_nm
//                        (0-40 nm); emission_width:each gives every baseline fluorophore its own
//   second_band:X        a second emission band of X (e.g. porphyrin's ~700 nm band): a Gaussian
//                        at center_nm (25-100 nm beyond X's peak), fwhm_nm (10-50 nm), with
//                        `ratio` times X's emitted energy (0-1.5); it scales with X
//   unknown_band         an emission band in no library spectrum: log-normal in wavenumber (the
//                        band shape of fluorescence, Siano & Metzler 1969) with center_nm (peak),
//                        fwhm_nm (8-150 nm), asymmetry (red/blue half-width ratio 0.4-2.5, 1 =
//                        Gaussian in wavenumber) and one amplitude per spectrum (found by a
//                        start grid; the free-form shape is estimated by unknown_band.h)
//   layered_tissue       each site's tissue is a layered stack (layered_site.h): per site
//                        thickness_mm:<site>, blood_fraction:<site>, saturation:<site>; the
//                        fluorophores the stack holds get depth-resolved columns
//   instrument_response  the instrument's spectral responsivity is off by a smooth factor:
//                        piecewise-linear log-gain at knots every ~40 nm over the fit range
//   bandwidth            the instrument blurs more than stated: global Gaussian fwhm_nm
//   emission_broadening  the tissue's fluorescence bands are broader than the library's (solution)
//                        spectra: global Gaussian fwhm_nm on the emission only, so unlike
//                        `bandwidth` it leaves the filter edge and the leak sharp
//   stray_light          a flat offset on the detector side (dark level, stray light): one level per
//                        spectrum; reported against the spectrum's recorded peak (fraction_of_peak,
//                        plausible up to 0.2), the tissue's mean signal (fraction) and the noise
//   longpass_leak        excitation light leaking through the long-pass in its blocked band: the
//                        light's spectrum times the filter's blocked fraction, one amplitude (the
//                        blocked band's transmission x the tissue's reflectance) per spectrum,
//                        reported as the filter's effective OD; offered whenever there is a
//                        long-pass, with or without a measured leak
//   longpass_edge        the long-pass edge sits elsewhere (angle, temperature): global shift_nm
// Camera (linear sensor baseline, one exposure gain):
//   channel_gain (gain_r, gain_b relative to green), crosstalk (6 off-diagonal fractions),
//   offset (per channel, DN), nonlinearity (gamma), qe_shift (delta_nm), nir_leak (transmittance
//   of the IR-cut filter beyond its edge).
#pragma once
#include <string>
#include <vector>

#include "renderer/diagnose/problem/diagnose_problem.h"
#include "renderer/spectral/spectra/sample_shapes.h"

namespace ofl {

enum class SpectraCause {
  kBlood, kExtraFluorophore, kShift, kBandwidth, kBroadening, kStray, kLeak, kEdge,
  kEmissionShift, kFluorShift, kFluorWidth, kFluorWidthEach, kSecondBand, kUnknownBand, kResponse, kLayered
};
enum class CameraCause { kGain, kCrosstalk, kOffset, kNonlinearity, kQeShift, kNirLeak };

// Which spectra candidates to try (model JSON "candidates").
struct SpectraCandidateOptions {
  bool blood = true;
  double blood_excitation_path_factor = 0;  // 0: blood attenuates the emission only
  bool extra_fluorophore = true;
  std::vector<std::string> extra_from;      // empty: every library fluorophore not in the baseline
  bool shift = true, bandwidth = true, broadening = true, stray = true, leak = true, edge = true;
  bool emission_shift = true;      // global, fluorescence only
  bool fluorophore_shape = true;   // emission_shift:X, emission_width:X, emission_width:each
  bool second_band = true;         // second_band:X
  bool unknown_band = true;
  bool instrument_response = true;
  // longpass_leak also carries the light's own transmission through the long-pass's passband (a
  // second amplitude): set when the baseline has no leak column ("leak": "none").
  bool leak_passband = false;
  // Plausible ranges by candidate id or name ("stray_light", "extra_fluorophore:teeth") and
  // quantity; replaces the default range of that quantity (model JSON "plausible").
  struct Range {
    std::string candidate, quantity;
    double lo, hi;
  };
  std::vector<Range> plausible;
};

// What the candidate list needs to know of each fluorophore.
struct FluorophoreInfo {
  std::string name;
  double peak_nm = 0;     // emission peak under its peak excitation
  bool baseline = false;  // in the baseline (else an extra_fluorophore candidate)
};
// The fit range (unknown band centres and the instrument response's knots).
struct SpectraRange {
  double min_nm = 470, max_nm = 750;
};

struct CameraCandidateOptions {
  bool gain = true, crosstalk = true, offset = true, nonlinearity = true, qe_shift = true, nir_leak = true;
};

std::vector<CandidateSpec> spectra_candidates(const SpectraCandidateOptions& o, const std::vector<FluorophoreInfo>& fluorophores,
                                              const SpectraRange& range);
SpectraCause spectra_cause(const CandidateSpec& c);
// The model's plausible ranges replace (or add) the candidates' own, by candidate id or name.
void apply_plausible(std::vector<CandidateSpec>& c, const std::vector<SpectraCandidateOptions::Range>& ranges);
// The fluorophore named by an extra_fluorophore candidate id ("extra_fluorophore:FAD" -> "FAD").
std::string extra_fluorophore_name(const CandidateSpec& c);
// The fluorophore a per-fluorophore cause acts on ("emission_shift:FAD" -> "FAD"; "" for global causes).
std::string cause_fluorophore(const CandidateSpec& c);
// Knot wavelengths of the instrument_response candidate over a fit range.
std::vector<double> response_knots(const SpectraRange& range);

// `signal_scale`: typical raw value (DN), so that offsets get sensible steps and bounds.
std::vector<CandidateSpec> camera_candidates(const CameraCandidateOptions& o, double signal_scale);
CameraCause camera_cause(const CandidateSpec& c);

// gaussian_blur and shift_samples: renderer/spectral/spectra/sample_shapes.h

}  // namespace ofl
