// Sampling routines with their densities (sample / pdf pairs), each covered by a chi-square test
// in tests/test_sampling.cpp.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "renderer/spectral/spectra/units.h"

namespace ofl {

// Cosine-weighted hemisphere around +z (Malley's method on a concentric disk); pdf = cos / pi.
glm::dvec3 sample_cosine_hemisphere(double u1, double u2);
inline double cosine_hemisphere_pdf(double cos_theta) { return cos_theta > 0 ? cos_theta / kPi : 0.0; }

// Uniform point on the unit disk (Shirley-Chiu concentric map); pdf = 1 / pi.
glm::dvec2 sample_concentric_disk(double u1, double u2);

// Uniform direction on the sphere; pdf = 1 / (4 pi).
glm::dvec3 sample_uniform_sphere(double u1, double u2);

// A discrete distribution: sample an index with probability w_i / sum w.
struct DiscreteDistribution {
  std::vector<double> cdf;  // cdf[i] = sum_{j <= i} p_j, last = 1
  std::vector<double> pmf;
  explicit DiscreteDistribution(const std::vector<double>& weights = {});
  bool empty() const { return cdf.empty(); }
  int sample(double u) const {
    int i = static_cast<int>(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin());
    return std::min(i, static_cast<int>(cdf.size()) - 1);
  }
  double pdf(int i) const { return pmf[i]; }
};

// DiscreteDistribution::sample without the binary search (for the camera wavelengths, drawn
// kLanes times per camera sample). The unit interval is cut into guide.size() cells; guide[j] is
// the bin itself (>= 0) where every u that can land in cell j, rounding of u * guide.size()
// included, falls in one bin, and otherwise -1 - the bin of the cell's start, from which sample(u)
// walks to the first CDF entry above u. With several cells per bin almost every u is answered by
// one table read. Gives exactly the bin DiscreteDistribution::sample(u) gives.
struct GuidedSampler {
  std::vector<double> cdf;
  std::vector<int> guide;
  explicit GuidedSampler(const DiscreteDistribution& d = DiscreteDistribution(), int per_bin = 4);
  int sample(double u) const {
    const int n = int(guide.size());
    const int g = guide[std::min(n - 1, int(std::max(0.0, u) * double(n)))];
    if (g >= 0) return g;
    const int last = int(cdf.size()) - 1;
    int i = -1 - g;
    while (i < last && cdf[i] <= u) ++i;  // the first bin whose CDF exceeds u...
    while (i > 0 && cdf[i - 1] > u) --i;  // ...whatever rounding did to the guide's index
    return i;
  }
};

// Orthonormal frame with z = n.
struct Frame {
  glm::dvec3 x, y, z;
  explicit Frame(const glm::dvec3& n);
  glm::dvec3 to_local(const glm::dvec3& v) const { return {v.x * x.x + v.y * x.y + v.z * x.z, v.x * y.x + v.y * y.y + v.z * y.z, v.x * z.x + v.y * z.y + v.z * z.z}; }
  glm::dvec3 to_world(const glm::dvec3& v) const { return v.x * x + v.y * y + v.z * z; }
};

}  // namespace ofl
