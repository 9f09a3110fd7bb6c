#include "renderer/render/trace/light_choice.h"

namespace ofl {

LightChoice::LightChoice(const std::vector<LedLight>& lights, const DiscreteDistribution& by_power, bool by_power_only)
    : lights_(lights), by_power_(by_power) {
  if (!by_power_only && !lights.empty() && int(lights.size()) <= kMaxWeighed) weighed_ = int(lights.size());
}

double LightChoice::weights(const glm::dvec3& p, const glm::dvec3& ns, const glm::dvec3& ng, double* w) const {
  double sum = 0;
  for (int i = 0; i < weighed_; ++i) sum += (w[i] = lights_[i].irradiance_bound(p, ns, ng));
  return sum;
}

LightPick LightChoice::pick(const glm::dvec3& p, const glm::dvec3& ns, const glm::dvec3& ng, double u) const {
  LightPick out;
  if (lights_.empty()) return out;
  if (by_power()) {
    out.light = by_power_.sample(u);
    out.pmf = by_power_.pdf(out.light);
    return out;
  }
  double w[kMaxWeighed];
  const double sum = weights(p, ns, ng, w);
  if (!(sum > 0)) return out;
  // Walk the running sum; the last LED with a positive weight takes what rounding leaves over.
  const double target = u * sum;
  double acc = 0;
  for (int i = 0; i < weighed_; ++i) {
    if (!(w[i] > 0)) continue;
    out.light = i;
    acc += w[i];
    if (target < acc) break;
  }
  out.pmf = w[out.light] / sum;
  return out;
}

double LightChoice::pmf(int light, const glm::dvec3& p, const glm::dvec3& ns, const glm::dvec3& ng) const {
  if (by_power()) return by_power_.pdf(light);
  double w[kMaxWeighed];
  const double sum = weights(p, ns, ng, w);
  return sum > 0 ? w[light] / sum : 0.0;
}

}  // namespace ofl
