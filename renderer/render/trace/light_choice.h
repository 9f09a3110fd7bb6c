// Which LED a surface point's next-event estimation goes to (docs/transport.md, "Light selection").
// Each LED is chosen with probability proportional to LedLight::irradiance_bound at the point: its
// unoccluded irradiance there for a point LED, a bound over the emitter for a disk. An LED that
// faces away from the point, whose angular profile is zero toward it, or that lies below the
// surface gets probability 0 and costs no shadow ray; the estimate stays unbiased because every
// LED that can light the point has a positive probability. A point no LED can light gets no light
// sample at all. With more than kMaxWeighed LEDs the choice is by power alone, as it was for every
// scene before (one weight per LED and vertex would then cost more than it saves).
#pragma once
#include <vector>

#include <glm/vec3.hpp>

#include "renderer/render/trace/sampling.h"
#include "renderer/scene/led_light.h"

namespace ofl {

struct LightPick {
  int light = -1;   // -1: no LED can light the point
  double pmf = 0;   // probability of having chosen `light`
};

class LightChoice {
 public:
  static constexpr int kMaxWeighed = 64;
  // by_power_only: choose by power at every point (IntegratorSpec::LightSelection::kPower).
  LightChoice(const std::vector<LedLight>& lights, const DiscreteDistribution& by_power, bool by_power_only = false);

  // Chooses an LED for the point p (shading normal ns, geometric normal ng, both on the side the
  // light must come from) with the uniform number u in [0, 1).
  LightPick pick(const glm::dvec3& p, const glm::dvec3& ns, const glm::dvec3& ng, double u) const;
  // The probability pick gives `light` at that point (for MIS when a sampled direction hits an LED).
  double pmf(int light, const glm::dvec3& p, const glm::dvec3& ns, const glm::dvec3& ng) const;
  bool by_power() const { return weighed_ == 0; }

 private:
  double weights(const glm::dvec3& p, const glm::dvec3& ns, const glm::dvec3& ng, double* w) const;

  const std::vector<LedLight>& lights_;
  const DiscreteDistribution& by_power_;
  int weighed_ = 0;  // number of LEDs weighed per point, 0 = by power
};

}  // namespace ofl
