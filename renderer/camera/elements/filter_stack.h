// The camera's optical filter stack: emission long-pass, NIR cut, band-passes, each either in
// front of the lens (the usual place for a fluorescence barrier filter) or near the sensor
// (cover glass / IR-cut on the sensor package). Interference filters move their spectrum toward
// the blue with the angle of incidence of the chief ray at their position,
//   lambda(theta) = lambda0 * sqrt(1 - (sin(theta) / n_eff)^2)        (docs/camera.md)
// so the stack's transmittance depends on the pixel. Absorbing (coloured-glass) filters set
// "interference": false and do not shift. Reflections between filters are ignored (the stack
// transmittance is the product of the filters').
#pragma once
#include <string>
#include <vector>

#include "renderer/spectral/spectra/optical_filter.h"
#include "renderer/spectral/spectra/spectrum.h"

namespace ofl {

enum class FilterPosition {
  kFrontOfLens,  // sees the object-side chief-ray angle (the field angle)
  kAtSensor      // sees the image-side chief-ray angle (lens "sensor_cra_deg", else the field angle)
};

struct StackedFilter {
  OpticalFilter filter;
  FilterPosition position = FilterPosition::kFrontOfLens;
};

struct FilterStack {
  std::vector<StackedFilter> filters;

  // Product of the filters' transmittances at `nm` for a pixel whose chief ray meets the
  // front-of-lens filters at `aoi_front_rad` and the sensor-side filters at `aoi_sensor_rad`.
  double transmittance(double nm, double aoi_front_rad = 0.0, double aoi_sensor_rad = 0.0) const;
  // The same as a Spectrum (kinks of measured tables moved with their shift).
  Spectrum at_angles(double aoi_front_rad = 0.0, double aoi_sensor_rad = 0.0) const;
  bool any_interference() const;
  bool empty() const { return filters.empty(); }
};

const char* filter_position_name(FilterPosition p);

}  // namespace ofl
