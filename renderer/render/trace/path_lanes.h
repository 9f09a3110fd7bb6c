// The wavelength lanes of one camera sample and a next-event light sample: what the path tracer's
// surface and layered-tissue vertices share.
#pragma once
#include <glm/vec3.hpp>

namespace ofl {

constexpr int kLanes = 8;

// The wavelength lanes of one camera sample.
struct PathLanes {
  int film[kLanes];        // camera wavelength (grid index) the lane reports to
  int wl[kLanes];          // current wavelength (grid index)
  float beta[kLanes];      // throughput, photon units
  float L[kLanes], Lf[kLanes];  // radiance gathered, and its fluorescent part
  bool fl[kLanes];         // the lane's light has been re-radiated (it is fluorescence)
  // The lane was re-radiated at the previous vertex. With deterministic direct excitation, next-event
  // estimation there already counted all LED light exciting that vertex (weight 1), so a BSDF-sampled
  // hit of an LED right after a re-radiation counts 0: a one-or-nothing partition instead of MIS,
  // because the directional MIS weights ignore how poorly the sampled excitation wavelength
  // matches a narrow LED line. Set only where next-event estimation summed the direct excitation.
  bool rerad_prev[kLanes];
  void add(int k, double v) {
    L[k] += float(v);
    if (fl[k]) Lf[k] += float(v);
  }
};

// One next-event sample toward an LED from a surface point, already tested for occlusion.
struct LightSample {
  bool valid = false;
  int light = -1, group = -1;
  glm::dvec3 wi;          // local direction to the light point (shading frame)
  // Irradiance on the surface per unit of the light's spectral shape, over the probability of this
  // sample: I0 P(theta) cos(surface) / r^2 / p(light). A BRDF times g times the shape is radiance.
  double g = 0;
  double pdf_solid = 0;   // solid-angle density of the light sample (disk LEDs), 0 for point LEDs (no MIS)
};

inline double power_heuristic(double a, double b) { return a * a / (a * a + b * b); }

}  // namespace ofl
