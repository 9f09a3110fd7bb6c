// Finding where light that travelled sideways under a surface comes back out: points of one mesh
// at a given distance from a centre point, by probe rays (docs/layered-tissue.md, "Lateral
// transport"). A radius r and an angle give a point in the plane through the centre perpendicular
// to one of three axes of the centre's frame (its normal, or one of the two tangents); the probe is
// the chord of the search sphere through that point along the axis, and every crossing of the
// chord with the same mesh is a candidate, one of which is chosen uniformly. The density of the
// chosen point per unit of surface area is the one-sample multiple-importance combination over
// the three axes: sum over axes a of P(axis a) p(r_a) |n . a| / hits, with r_a the distance from
// the centre projected on the plane perpendicular to a and p the planar density of the radius. On a
// flat surface the normal axis finds every point (once); where the surface bends away, the
// tangent axes find what the normal one misses.
#pragma once
#include <array>
#include <functional>

#include <glm/vec3.hpp>

#include "renderer/render/trace/embree_scene.h"
#include "renderer/render/trace/sampling.h"

namespace ofl {

constexpr int kMaxProbeHits = 8;
inline constexpr std::array<double, 3> kProbeAxisProbability = {0.9, 0.05, 0.05};  // normal, tangent x, tangent y

struct ProbeResult {
  bool found = false;
  SurfacePoint sp;  // the chosen point (material resolved, regions included)
  int hits = 0;     // crossings of the chord with the mesh
  int axis = 0;
};

// The crossings of the segment a -> b with mesh geometry `geom` (at most kMaxProbeHits), nearest first.
int probe_segment(const EmbreeScene& e, unsigned geom, const glm::dvec3& a, const glm::dvec3& b, SurfacePoint* out);

// A point of `geom` at planar distance r_mm from `centre`, angle phi, probing along axis `axis`
// (0: frame.z, 1: frame.x, 2: frame.y) through a search sphere of radius search_mm; u picks among
// the crossings. Scene units are metres.
ProbeResult probe_around(const EmbreeScene& e, unsigned geom, const glm::dvec3& centre, const Frame& frame, double r_mm,
                         double phi, int axis, double search_mm, double u);

// The area density (1/mm^2) of point x found by probe_around from `centre`, given the planar
// density of the radius (1/mm^2 as a function of r in mm) and the number of crossings its probe met.
double probe_density(const glm::dvec3& centre, const Frame& frame, const SurfacePoint& x, int hits,
                     const std::function<double(double)>& planar_density);

}  // namespace ofl
