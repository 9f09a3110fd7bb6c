// Everything the path tracer looks up per wavelength lane, prepared once per render in float:
// per material its tables (material_tables.h); per light its spectral shape; the film's band
// weights and the wavelength sampling distribution.
#pragma once
#include <vector>

#include "renderer/render/material/material_tables.h"
#include "renderer/render/trace/sampling.h"
#include "renderer/scene/scene.h"

namespace ofl {

struct RenderTables {
  int n = 0;
  WavelengthGrid grid;
  std::vector<MaterialTables> materials;
  std::vector<std::vector<float>> light_shape;  // [spd group][lambda] photons per (W/sr), unit I0
  std::vector<int> light_group;                  // light -> spd group
  std::vector<float> light_scale;                // light -> I0 in W/sr (after filters: intensity_W_sr)
  DiscreteDistribution light_select;             // by power
  // Film: band weights of each grid index, and how camera wavelengths are sampled.
  struct BandWeight { int band; float weight; };
  std::vector<std::vector<BandWeight>> band_weights;  // [grid index]
  DiscreteDistribution wavelength_pdf;                // over grid indices
  std::vector<double> film_scale;                     // [grid index] photon energy / pdf
  int bands = 0;

  RenderTables(const Scene& scene, const std::vector<double>& wavelength_importance = {});
};

}  // namespace ofl
