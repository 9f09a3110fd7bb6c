// A radially symmetric distribution on the plane, tabulated on rings: how far from where light
// entered a layered stack it comes back out (docs/layered-tissue.md, "Lateral transport").
//
// The rings are shared by every profile of a stack: ring j covers [e_j, e_{j+1}) with
// e_j = r_max (j / R)^2, fine near the entry point (where violet light returns) and wider out to
// r_max (where only red light gets). Inside a ring the density per unit area is constant, so a
// profile is its ring masses m_j (summing to 1 over the rings): the density at radius r is
// m_j / (pi (e_{j+1}^2 - e_j^2)), the mass within radius r grows linearly in r^2 inside a ring, and
// sampling picks a ring by its mass and then r^2 uniformly in the ring. Mass beyond r_max is not
// kept: the fill renormalises what is inside, so the profile only moves light, never loses it.
// Lengths are millimetres.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

namespace ofl {

struct RadialRings {
  double r_max = 20.0;  // mm
  int rings = 64;

  double edge(int j) const {
    const double t = double(j) / rings;
    return r_max * t * t;
  }
  // The ring holding radius r, or -1 at or beyond r_max.
  int ring_of(double r) const {
    if (!(r >= 0) || r >= r_max) return -1;
    int j = int(rings * std::sqrt(r / r_max));
    return std::min(j, rings - 1);
  }
  double area(int j) const {
    const double a = edge(j), b = edge(j + 1);
    return 3.14159265358979323846 * (b * b - a * a);
  }
};

// One profile's ring masses at `mass` (R values) with their running sums at `cdf` (R values,
// cdf[j] = sum of mass[0..j], the last one 1). Free functions over plain arrays, so that tables
// of many profiles stay flat vectors.
namespace radial {

// Density per unit area (1/mm^2) at radius r.
inline double density(const RadialRings& g, const float* mass, double r) {
  const int j = g.ring_of(r);
  return j < 0 ? 0.0 : mass[j] / g.area(j);
}

// Mass within radius r (0..1).
inline double cumulative(const RadialRings& g, const float* cdf, const float* mass, double r) {
  if (!(r > 0)) return 0.0;
  const int j = g.ring_of(r);
  if (j < 0) return cdf[g.rings - 1];
  const double a = g.edge(j), b = g.edge(j + 1);
  const double below = j > 0 ? cdf[j - 1] : 0.0;
  return below + mass[j] * (r * r - a * a) / (b * b - a * a);
}

// A radius drawn from the profile: u1 picks the ring, u2 the place inside it (uniform in area).
inline double sample(const RadialRings& g, const float* cdf, double u1, double u2) {
  const float* end = cdf + g.rings;
  int j = int(std::upper_bound(cdf, end, float(u1)) - cdf);
  j = std::min(j, g.rings - 1);
  const double a = g.edge(j), b = g.edge(j + 1);
  return std::sqrt(a * a + u2 * (b * b - a * a));
}

// Normalises R tallies to unit mass and writes their running sums; returns the total before
// normalisation (0: an empty profile, left as all mass in the first ring so that sampling stays
// defined; its weight is 0 wherever it is used).
inline double normalise(int rings, const double* tally, float* mass, float* cdf) {
  double total = 0;
  for (int j = 0; j < rings; ++j) total += std::max(0.0, tally[j]);
  double acc = 0;
  for (int j = 0; j < rings; ++j) {
    const double m = total > 0 ? std::max(0.0, tally[j]) / total : (j == 0 ? 1.0 : 0.0);
    mass[j] = float(m);
    acc += m;
    cdf[j] = float(acc);
  }
  cdf[rings - 1] = 1.0f;
  return total;
}

}  // namespace radial

}  // namespace ofl
