#include "renderer/render/trace/sampling.h"

#include <glm/geometric.hpp>

namespace ofl {

glm::dvec2 sample_concentric_disk(double u1, double u2) {
  double a = 2 * u1 - 1, b = 2 * u2 - 1;
  if (a == 0 && b == 0) return {0, 0};
  double r, phi;
  if (std::fabs(a) > std::fabs(b)) { r = a; phi = (kPi / 4) * (b / a); }
  else { r = b; phi = kPi / 2 - (kPi / 4) * (a / b); }
  return {r * std::cos(phi), r * std::sin(phi)};
}

glm::dvec3 sample_cosine_hemisphere(double u1, double u2) {
  glm::dvec2 d = sample_concentric_disk(u1, u2);
  double z = std::sqrt(std::max(0.0, 1.0 - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}

glm::dvec3 sample_uniform_sphere(double u1, double u2) {
  double z = 1 - 2 * u1;
  double r = std::sqrt(std::max(0.0, 1 - z * z));
  double phi = 2 * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

DiscreteDistribution::DiscreteDistribution(const std::vector<double>& w) {
  double sum = 0;
  for (double v : w) sum += std::max(0.0, v);
  if (!(sum > 0)) return;
  double acc = 0;
  for (double v : w) {
    pmf.push_back(std::max(0.0, v) / sum);
    acc += pmf.back();
    cdf.push_back(acc);
  }
  cdf.back() = 1.0;
}

GuidedSampler::GuidedSampler(const DiscreteDistribution& d, int per_bin) : cdf(d.cdf) {
  if (cdf.empty()) cdf = {1.0};  // an empty distribution: bin 0, as DiscreteDistribution gives
  const size_t n = size_t(std::max(1, per_bin)) * cdf.size();
  // A u that lands in cell j lies within a rounding step of [j, j + 1) / n; the margin is far wider.
  constexpr double kMargin = 1e-12;
  for (size_t j = 0; j < n; ++j) {
    if (d.empty()) {
      guide.push_back(0);
      continue;
    }
    const int start = d.sample(double(j) / double(n));
    const int lo = d.sample(std::max(0.0, double(j) / double(n) - kMargin));
    const int hi = d.sample(double(j + 1) / double(n) + kMargin);
    guide.push_back(lo == hi ? lo : -1 - start);
  }
}

Frame::Frame(const glm::dvec3& n) : z(n) {
  // Duff et al. 2017 branchless orthonormal basis.
  double sign = std::copysign(1.0, n.z);
  double a = -1.0 / (sign + n.z);
  double b = n.x * n.y * a;
  x = {1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x};
  y = {b, sign + n.y * n.y * a, -n.y};
}

}  // namespace ofl
