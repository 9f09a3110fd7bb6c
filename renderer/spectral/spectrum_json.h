// Spectra and filters as written in scene, camera and model files. A spectrum may be:
//   0.5                                   constant
//   "../assets/spectra/x.csv"             a two-column CSV
//   {"type": "csv", "file": "...", "column": "tongue", "scale": 0.01, "clip_negative": false,
//    "outside": "zero" | "clamp"}
//   {"type": "points", "points": [[400, 0.1], [700, 0.6]]}     piecewise linear
//   {"type": "gaussian", "peak_nm": 385, "fwhm_nm": 12}
//   {"type": "blackbody", "temperature_K": 3000}
//   {"type": "longpass" | "shortpass" | "bandpass", ...filter fields...}
//   {"type": "product", "factors": [<spectrum>, ...]}
//   {"type": "sum", "terms": [<spectrum>, ...], "weights": [1.0, 0.6]}   e.g. a phosphor white LED
// Relative file paths are relative to the file that names them.
#pragma once
#include "renderer/core/files/json_node.h"
#include "renderer/spectral/spectra/optical_filter.h"
#include "renderer/spectral/spectra/spectrum.h"

namespace ofl {

enum class SpectrumKind {
  kReflectance,   // 0..1, tables clamp outside their range
  kEmission,      // >= 0, tables are zero outside their range
  kTransmittance  // 0..1, tables are zero outside their range
};

Spectrum parse_spectrum(const JsonNode& node, SpectrumKind kind);
// Filter fields: {"type": "longpass", "edge_nm": 475, "width_nm": 5, "od": 4, "peak": 0.95,
//   "interference": true, "n_eff": 2.0} or {"type": "measured", "file": "...", "column": "...",
//   "interference": true, "n_eff": 1.8}.
OpticalFilter parse_filter(const JsonNode& node);

// Checks a tabulated spectrum against its kind (finite, >= 0, <= 1 for reflectance and
// transmittance) and reports the first bad wavelength.
void check_tabulated(const JsonNode& node, const std::vector<double>& values,
                     const WavelengthGrid& grid, SpectrumKind kind);

}  // namespace ofl
