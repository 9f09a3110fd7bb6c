// The flat patch a spectrum's material is rendered on: a 10 cm quad lit by the measured LED and
// seen from above. Both sides of the loop use it: the layered_tissue cause fills its depth-resolved
// columns from a patch of the stack (layered_site.h), and closing the loop renders the diagnosed
// material on it (render_loop.h).
#pragma once
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

struct PatchRenderOptions {
  int resolution = 32;     // pixels per side
  int spp = 1024;          // samples per pixel: 1M camera samples, ~0.4 % noise per 2 nm band
  uint64_t seed = 1;
  double margin_nm = 30;   // bands cover the model's fit range +- this (clipped to the grid)
  // Return the fluorescence the renderer tallies separately, not the total radiance. The reflected
  // excitation is then the diagnosis' leak column (a white target measured through the filters,
  // free amplitude), as in the diagnosis: the measured LED spectra's tails beyond the LED band
  // are mostly the spectroradiometer's own stray light (oe_tongue_lip, 450 nm LED at 480 nm: 35x
  // what the white target shows through the long-pass), so a patch reflecting them would not be
  // the measured light.
  bool fluorescence_only = true;
};

// A flat-patch scene: `material` on a 10 cm quad at the origin, a point LED at 45 degrees 10 cm
// away aimed at its centre whose spectrum is `excitation` (bin values on `grid`) with the
// intensity that gives a white Lambertian patch at the centre exactly that radiance, a pinhole
// camera 10 cm above looking down (2 degree field, so the patch fills the image), max_depth 1,
// transport grid `grid`, one output band per grid bin over [band_min_nm, band_max_nm].
nlohmann::json flat_patch_scene(const nlohmann::json& material, const WavelengthGrid& grid,
                                const std::vector<double>& excitation, double band_min_nm, double band_max_nm,
                                const PatchRenderOptions& o = {});

}  // namespace ofl
