#include "renderer/camera/elements/filter_stack.h"

#include <algorithm>

namespace ofl {

double FilterStack::transmittance(double nm, double aoi_front, double aoi_sensor) const {
  double t = 1.0;
  for (const auto& f : filters)
    t *= f.filter.transmittance(nm, f.position == FilterPosition::kFrontOfLens ? aoi_front : aoi_sensor);
  return t;
}

Spectrum FilterStack::at_angles(double aoi_front, double aoi_sensor) const {
  std::vector<Spectrum> parts;
  for (const auto& f : filters)
    parts.push_back(f.filter.at_angle(f.position == FilterPosition::kFrontOfLens ? aoi_front : aoi_sensor));
  if (parts.empty()) return constant_spectrum(1.0);
  return product_spectrum(parts);
}

bool FilterStack::any_interference() const {
  return std::any_of(filters.begin(), filters.end(), [](const StackedFilter& f) { return f.filter.interference; });
}

const char* filter_position_name(FilterPosition p) {
  return p == FilterPosition::kFrontOfLens ? "front" : "sensor";
}

}  // namespace ofl
