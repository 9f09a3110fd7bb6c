#include "renderer/render/stack/stack_walk.h"

namespace ofl {

StackWalker::Boundary StackWalker::cross(WalkState& s, WalkLanes& lanes, Rng& rng, glm::dvec3* exit_dir) const {
  const int last = int(st_.layers.size()) - 1;
  const bool up = s.d.z > 0;
  const double n1 = st_.layers[s.layer].ior;
  auto scale = [&](double f) {
    for (int k = 0; k < lanes.count; ++k) lanes.w[k] = float(lanes.w[k] * f);
  };
  if (up && s.layer == 0) {
    // The top interface, possibly rough.
    InterfaceEvent e = st_.top.scatter(s.d, rng);
    if (e.weight <= 0) return Boundary::kLost;
    if (e.transmitted) {
      scale(e.weight * crossing_factor(n1, st_.ambient_ior));
      *exit_dir = e.dir;
      return Boundary::kExitTop;
    }
    scale(e.weight);
    s.d = e.dir;
    s.direct = false;
    return Boundary::kContinue;
  }
  // A smooth interface to the neighbouring layer or to the clear space below the stack.
  const bool below = !up && s.layer == last;
  const double n2 = below ? st_.below_ior : st_.layers[s.layer + (up ? -1 : 1)].ior;
  if (n1 == n2) {
    if (below) {
      *exit_dir = s.d;
      return Boundary::kExitBottom;
    }
    s.layer += up ? -1 : 1;
    return Boundary::kContinue;
  }
  double F = fresnel_dielectric(std::abs(s.d.z), n2 / n1);
  glm::dvec3 t;
  if (rng.next_double() < F || !refract_smooth(s.d, n1 / n2, &t)) {
    s.d.z = -s.d.z;
    s.direct = false;
    return Boundary::kContinue;
  }
  scale(crossing_factor(n1, n2));
  s.d = t;
  if (below) {
    *exit_dir = t;
    return Boundary::kExitBottom;
  }
  s.layer += up ? -1 : 1;
  return Boundary::kContinue;
}

void StackWalker::scatter_lanes(WalkState& s, WalkLanes& lanes, const LaneCoefficients& c, const float* fac, double g,
                                Rng& rng) const {
  const StackLayerTables& L = st_.layers[s.layer];
  bool fluor[kWalkLanes] = {};
  int active = 0, reradiated = 0;
  for (int k = 0; k < lanes.count; ++k) {
    if (lanes.w[k] == 0) continue;
    float a = c.mus[k] + c.kappa[k];
    if (!(a > 0)) {
      lanes.w[k] = 0;
      continue;
    }
    ++active;
    fluor[k] = c.kappa[k] > 0 && rng.next_float() * a >= c.mus[k];
    reradiated += fluor[k];
    lanes.w[k] *= a;
  }
  if (active == 0) return;
  // One new direction for all lanes from the mixture of the lobes the lanes chose.
  const double p_iso = double(reradiated) / active;
  glm::dvec3 d = rng.next_double() < p_iso ? sample_uniform_sphere(rng.next_double(), rng.next_double())
                                           : sample_hg(g, s.d, rng.next_double(), rng.next_double());
  const double hg = hg_phase(g, glm::dot(d, s.d));
  const double iso = 1.0 / (4.0 * kPi);
  const double pdf = p_iso * iso + (1.0 - p_iso) * hg;
  for (int k = 0; k < lanes.count; ++k) {
    if (lanes.w[k] == 0) continue;
    lanes.w[k] = float(lanes.w[k] * (fluor[k] ? iso : hg) / pdf);
    lanes.rerad[k] = fluor[k];
    if (fluor[k]) {
      lanes.wl[k] = sample_layer_excitation(L, fac, lanes.wl[k], rng.next_float(), n_);
      lanes.fl[k] = true;
      lanes.vrerad[k] = true;
    }
  }
  s.d = d;
}

bool StackWalker::roulette(WalkLanes& lanes, float w_ref, Rng& rng) const {
  // Below a tenth of the weight the walk started with, survive with probability m / (0.1 w_ref).
  const float m = lanes.max_weight();
  const float floor = 0.1f * w_ref;
  if (m >= floor) return true;
  if (!(m > 0)) return false;
  float q = m / floor;
  if (rng.next_float() >= q) return false;
  for (int k = 0; k < lanes.count; ++k) lanes.w[k] /= q;
  return true;
}

}  // namespace ofl
