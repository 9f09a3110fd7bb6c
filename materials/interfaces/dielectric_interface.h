// A plane dielectric interface between two media, smooth (Fresnel mirror and Snell refraction) or
// rough (GGX microfacets, Walter et al. 2007, sampled through the visible normals), as the layered
// tissue's random walk meets it. Directions are travel directions in the local frame (z = the
// interface normal, pointing up, from the medium below to the medium above).
//
// Weights are power ratios, without the n^2 radiance factor (the walk applies that itself in
// radiance mode). A smooth interface reflects with probability F and refracts otherwise, weight 1.
// A rough one samples a microfacet normal m from the normals visible from the incident direction,
// then reflects with probability F(m) or refracts, also with weight 1. Single-scattering microfacet
// theory loses the samples that leave on the wrong side of the mean surface (they would hit another
// facet); here such a sample is drawn again, so the interface is lossless, as a real one is (the
// lost part is up to 20 % for light trapped under a wet film by total internal reflection). The
// BSDF this defines is the single-scattering one divided by the probability V(mu) that a sample
// from incidence cosine mu is valid; evaluations that must agree with the sampling (next-event
// estimation through the top, the top's specular lobe) divide by the same V, tabulated here.
#pragma once
#include <array>

#include <glm/vec3.hpp>

#include "materials/interfaces/coated.h"

namespace ofl {

struct InterfaceEvent {
  glm::dvec3 dir{0, 0, 0};  // travel direction afterwards
  double weight = 0;        // 0 = no valid outcome
  bool transmitted = false;
};

class DielectricInterface {
 public:
  DielectricInterface() = default;
  // alpha: GGX roughness (0 = smooth); indices of the media above and below.
  DielectricInterface(double alpha, double n_above, double n_below);
  bool smooth() const { return alpha_ <= 0; }
  double alpha() const { return alpha_; }
  double n_above() const { return n_above_; }
  double n_below() const { return n_below_; }

  // The path travelling along `d` hits the interface; reflects or refracts by Fresnel (u0, and
  // further random numbers from `rng_next` when a rough sample must be drawn again).
  template <class Rng>
  InterfaceEvent scatter(const glm::dvec3& d, Rng& rng) const;
  // Refraction only, sampled from the side of `d`: the transmitted direction w and the weight that
  // makes it an estimate of the BTDF scatter() samples from the other side (light going from w back
  // through the interface): (1 - F(m)) G1(w) / (G1(d) V(w)), 0 on total internal reflection. Used to
  // connect a point inside the stack with a direction outside (next-event estimation).
  InterfaceEvent transmit(const glm::dvec3& d, double u1, double u2) const;
  // The probability V that a rough sample from travel direction d is valid (1 when smooth).
  double valid_fraction(const glm::dvec3& d) const;
  // Reflection BRDF of scatter() for light from wi seen from wo, both above: F D G1(wo) / (4 wo.z wi.z V(wo)).
  double reflection(const glm::dvec3& wo, const glm::dvec3& wi) const;

 private:
  // Travel direction d seen from its incident side (turned to +z when d travels up): the direction
  // back along the path, a sampled visible microfacet normal, their cosine and the index ratio.
  struct Incidence {
    bool flipped = false;
    glm::dvec3 wo{0, 0, 1}, m{0, 0, 1};
    double ci = 0, eta = 1;
  };
  Incidence incidence(const glm::dvec3& d, double u1, double u2) const;
  InterfaceEvent try_once(const glm::dvec3& d, double u0, double u1, double u2) const;
  double alpha_ = 0, n_above_ = 1, n_below_ = 1;
  GgxCoating ggx_;
  static constexpr int kTable = 64;
  std::array<double, kTable> valid_from_above_{}, valid_from_below_{};
};

template <class Rng>
InterfaceEvent DielectricInterface::scatter(const glm::dvec3& d, Rng& rng) const {
  for (int tries = 0; tries < 64; ++tries) {
    InterfaceEvent e = try_once(d, rng.next_double(), rng.next_double(), rng.next_double());
    if (e.weight > 0 || smooth()) return e;
  }
  return {};  // only at incidences so grazing that V is below ~1e-6
}

// Snell refraction of travel direction d at a smooth interface of normal z (eta = n_from / n_to);
// returns false on total internal reflection.
bool refract_smooth(const glm::dvec3& d, double eta, glm::dvec3* out);

}  // namespace ofl
