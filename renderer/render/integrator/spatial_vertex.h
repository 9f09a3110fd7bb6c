// Layered tissue with lateral transport ("transport": "spatial"): at a camera-path vertex on such
// a material, light leaves at the vertex x_o but entered elsewhere (docs/layered-tissue.md,
// "Lateral transport"). The stack's BSSRDF is taken as separable: the position-free table's
// directional response (renderer/render/stack/stack_response.h) times a radial profile from
// stack_profiles.h. Per vertex, with one LED chosen by power and one point on it for every
// connection the vertex makes:
// 1. The top interface's specular lobe stays at x_o (closed form, next-event estimation there).
// 2. The anchor: the position-free table's next-event estimate at x_o (reflected and fluorescent).
// 3. Two subsurface strategies, each run with a probability that follows what it is expected to add
//    (the larger always; both when the path continues from its entry), its estimates divided by it:
//    - elastic: an entry point x_i at distance r drawn from the elastic exit profile of the lanes'
//      wavelengths (for the viewer's cosine; by reciprocity where light leaving toward the viewer
//      entered), found on the mesh by a probe ray (renderer/render/spatial/surface_probe.h);
//    - fluorescent: a depth slice Z and an emission point x_m under the surface, displaced from x_o
//      by the emission leg (the spread of the emission wavelength from depth Z), then x_i displaced
//      from x_m by the excitation leg (the spread of the LED's light down to Z). The fluorophores at
//      x_m are those of the material found at x_m, so a lesion's fluorescence comes from inside
//      the lesion and is blurred by the emission's own spread.
//    Next-event estimation to the LED from x_i adds what the spatial transport sends through x_i
//    minus what x_o's own material would send through the same displacements lit as x_o is (the
//    anchor's integrand): a control variate whose integral is the anchor, so that even light on one
//    material leaves nothing to sample. Reflected light with MIS against the continuation; the
//    deterministic sum over the LED's bins for fluorescence (as everywhere else).
// 4. The continuation is the top lobe's reflection from x_o, or leaves x_i (cosine lobe) carrying
//    the chosen strategy's lanes (fluorescent lanes move to an excitation wavelength drawn from the
//    table).
// Across `regions`: reflected light takes the product of the crossed materials' BSSRDFs, each raised
// to its share of the path from x_i to x_o (a vertical passage at each end through the layers that
// tell the materials apart, and the part of the segment between them that runs among those layers);
// fluorescence the fluorophores at the emission point, each leg weighed the same way with one passage,
// under its surface end (docs/layered-tissue.md, "Regions and lateral transport").
#pragma once
#include <algorithm>
#include <cmath>

#include "renderer/render/integrator/render_tables.h"
#include "renderer/render/trace/embree_scene.h"
#include "renderer/render/trace/path_lanes.h"
#include "renderer/render/trace/ray_counts.h"
#include "renderer/render/trace/rng.h"
#include "renderer/render/trace/sampling.h"

namespace ofl {

struct SpatialScatter {
  bool ok = false;         // the path continues
  SurfacePoint from;       // where it continues from (x_o or x_i)
  glm::dvec3 wi_world{0, 0, 0};
  double pdf = 0;          // MIS density for an LED hit along wi_world; 0 = count it fully
  bool reflected = false;  // the continuation is the top interface's reflection at x_o
};

// The vertical passages of a path that crosses regions are counted down to this depth at most (mm).
constexpr double kPassageMm = 1.0;
// The depth (mm) within the top kPassageMm over which two stacks differ (their layers at that depth
// differ in thickness, index, anisotropy, absorption, scattering or fluorophores), read at 0.01 mm
// steps: the length of the vertical passage through the layers that tell two regions apart.
double differing_depth_mm(const LayerStack& a, const LayerStack& b);
// The length of a chord of r mm between two ends that a path spends among the layers of depth
// L mm that tell two regions apart: r when r is short against L; the light between the ends of a
// long path runs about r / 2 deep, below those layers, so at most 2 L (docs/layered-tissue.md,
// "Regions and lateral transport"). 0 when L is 0.
inline double chord_among_passages_mm(double r, double L) { return L > 0 ? r / (1.0 + r / (2.0 * L)) : 0.0; }
// A material's share of a path across regions (docs/layered-tissue.md, "Regions and lateral
// transport"): `ends_in_m` of its `n_ends` vertical passages of `passage` mm lie in the material, and
// of the chord between them `along` mm run among the layers that differ, `chord_share` of it in the
// material. The chord's own share where there is nothing to count.
inline double passage_share(double chord_share, int ends_in_m, int n_ends, double passage, double along) {
  const double total = n_ends * passage + along;
  return total > 0 ? (ends_in_m * passage + along * chord_share) / total : chord_share;
}

// The darker materials' weight in a crossing (docs/layered-tissue.md, "Regions and lateral
// transport"): light crossing between regions wanders beside its straight path and loses more to the
// more absorbing side than the chord's shares say. The n materials are ordered by their diffuse
// reflectance at the lane's wavelength, darkest first, and the cumulative share D_i of the i darkest
// becomes D_i^gamma; out[j] is material j's new share (they still sum to one, and a material without
// a share keeps none). gamma = 1 leaves the shares; kDarkerShareGamma was measured on the lesion
// discs against the 3D forward Monte Carlo.
constexpr double kDarkerShareGamma = 0.8;
inline void darker_shares(int n, const double* share, const double* reflectance, double gamma, double* out) {
  constexpr int kMaxShares = 8;
  int order[kMaxShares];
  n = n < kMaxShares ? n : kMaxShares;
  for (int i = 0; i < n; ++i) {
    int j = i;
    while (j > 0 && reflectance[order[j - 1]] > reflectance[i]) {
      order[j] = order[j - 1];
      --j;
    }
    order[j] = i;
  }
  double cum = 0, prev = 0;
  for (int i = 0; i < n; ++i) {
    cum += share[order[i]];
    const double now = i == n - 1 ? 1.0 : std::pow(std::min(std::max(cum, 0.0), 1.0), gamma);
    out[order[i]] = share[order[i]] > 0 ? std::max(now - prev, 0.0) : 0.0;
    prev = share[order[i]] > 0 ? now : prev;
  }
}

class SpatialTransport {
 public:
  SpatialTransport(const Scene& scene, const EmbreeScene& embree, const RenderTables& tables);

  // xo: the vertex (normals facing the viewer), geom: its Embree geometry (probes look for points of
  // the same mesh), wo: local direction to the viewer in `frame`. Adds the light gathered to the
  // lanes' L/Lf and updates their throughput, wavelength and flags for the continuation.
  SpatialScatter scatter(const SurfacePoint& xo, unsigned geom, const Frame& frame, const glm::dvec3& wo,
                         const MaterialTables& mt, PathLanes& p, Rng& rng, RayCounts& counts, RayLog* log) const;

 private:
  struct Vertex;
  struct Entry;
  struct Chord;
  // The probabilities of running each subsurface strategy's next-event estimation (beyond the one the
  // path continues from) and of continuing from the fluorescent strategy's entry.
  struct Plan {
    double run_el = 0, run_fl = 0, cont_fl = 0;
  };
  Plan plan(const Vertex& v) const;
  LightSample connect(const Vertex& v, const SurfacePoint& x, const Frame& f, RayCounts& counts, RayLog* log) const;
  void anchor(Vertex& v, const Plan& pl, RayCounts& counts, RayLog* log) const;
  void top_light(Vertex& v) const;
  Entry sample_elastic(Vertex& v, Rng& rng, RayCounts& counts) const;
  Entry sample_fluorescent(Vertex& v, Rng& rng, RayCounts& counts) const;
  void chord_materials(const Vertex& v, const SurfacePoint& a, const SurfacePoint& b, Chord& c) const;
  Chord crossing_shares(const Chord& chord, int mo, int mi, double r_mm) const;
  Chord leg_shares(const Chord& chord, int surface, int emitter, double rho_mm, double z_mm) const;
  double passage_among(const Chord& chord, int end, int other) const;
  Chord with_passages(const Chord& chord, const int* ends, int n_ends, double passage, double along) const;
  void elastic_values(const Vertex& v, const Entry& e, double mu_i, double* f) const;
  void fluorescent_values(const Vertex& v, const MaterialTables& m, const Entry& e, const LightSample& ls, double rho_i,
                          double* f) const;
  void fluorescent_crossing(const Vertex& v, const Entry& e, int group, double mu_i, double* out) const;
  void entry_light(Vertex& v, Entry& e, RayCounts& counts, RayLog* log) const;
  SpatialScatter continue_at_entry(Vertex& v, Entry& e, Rng& rng) const;
  SpatialScatter continue_at_top(Vertex& v, Rng& rng) const;
  bool spatial_material(int material) const;

  const Scene& scene_;
  const EmbreeScene& embree_;
  const RenderTables& t_;
  // The widest search radius of the scene's spatial stacks (mm): a small share of the entry and
  // emission points is drawn uniformly over this disc (spatial_vertex.cpp, kDefensive), so that a
  // neighbouring material whose profile reaches where x_o's does not is still sampled.
  double wide_mm_ = 0;
  // Per pair of materials (row-major over the scene's materials), the depth in mm, within the top
  // kPassageMm, over which their stacks differ: the vertical passage each end of a crossing path
  // makes through the layers that tell the two apart (elastic_values).
  std::vector<double> passage_mm_;
};

}  // namespace ofl
