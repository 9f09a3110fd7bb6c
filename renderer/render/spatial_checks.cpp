// Geometry checks of the spatial transport (see spatial_checks.h).
#include "renderer/render/spatial_checks.h"

#include <cmath>
#include <cstdio>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "renderer/render/spatial/spatial_tables.h"
#include "renderer/render/trace/rng.h"

namespace ofl {

namespace {

constexpr int kThicknessSamples = 256;
constexpr double kThinShare = 0.05;  // warn when more of the area than this is thin

// The radius (mm) holding 90 % of the elastic exit profile at normal incidence, largest over the
// bins the render uses that reflect at least 1 %.
double r90_mm(const SpatialStack& s, int used) {
  double r = 0;
  const RadialRings& g = s.el_rings();
  for (int wl = 0; wl < std::min(used, s.n); ++wl) {
    if (s.prof->rd[wl] < 0.01) continue;
    const float* cdf = &s.el_cdf[s.el_at(0, wl)];
    const float* mass = &s.el_mass[s.el_at(0, wl)];
    int j = 0;
    while (j + 1 < g.rings && cdf[j] < 0.9f) ++j;
    const double below = j > 0 ? cdf[j - 1] : 0.0, a = g.edge(j), b = g.edge(j + 1);
    const double t = mass[j] > 0 ? (0.9 - below) / mass[j] : 0.0;
    r = std::max(r, std::sqrt(a * a + std::clamp(t, 0.0, 1.0) * (b * b - a * a)));
  }
  return r;
}

// The spatial materials a scene material stands for (itself, or a regions material's members).
std::vector<int> spatial_members(const Scene& sc, const RenderTables& t, int m) {
  std::vector<int> out;
  if (m < 0) return out;
  std::vector<int> cand = {m};
  if (sc.materials[m].dispatches()) {
    cand = {sc.materials[m].regions_base};
    for (const auto& r : sc.materials[m].regions) cand.push_back(r.material);
  }
  for (int c : cand)
    if (c >= 0 && t.materials[c].stack.spatial) out.push_back(c);
  return out;
}

// Share of a mesh's directed edges that another triangle traverses the same way.
double inconsistent_edges(const TriangleMesh& mesh) {
  std::unordered_map<uint64_t, int> seen;
  const size_t tris = mesh.indices.size() / 3;
  for (size_t t = 0; t < tris; ++t)
    for (int e = 0; e < 3; ++e) {
      const uint64_t a = mesh.indices[3 * t + e], b = mesh.indices[3 * t + (e + 1) % 3];
      ++seen[(a << 32) | b];
    }
  size_t bad = 0;
  for (const auto& [k, n] : seen)
    if (n > 1) bad += n;
  return seen.empty() ? 0.0 : double(bad) / double(3 * tris);
}

// Share of a mesh's area where another part of it lies within `limit_m` along the normal.
double thin_share(const EmbreeScene& e, unsigned geom, const TriangleMesh& mesh, double limit_m) {
  const size_t tris = mesh.indices.size() / 3;
  std::vector<double> cdf(tris);
  double acc = 0;
  for (size_t t = 0; t < tris; ++t) {
    const glm::dvec3 p0 = mesh.positions[mesh.indices[3 * t]], p1 = mesh.positions[mesh.indices[3 * t + 1]],
                     p2 = mesh.positions[mesh.indices[3 * t + 2]];
    acc += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
    cdf[t] = acc;
  }
  if (!(acc > 0)) return 0.0;
  int thin = 0;
  for (int i = 0; i < kThicknessSamples; ++i) {
    Rng rng(0x5448494EULL, uint64_t(i));
    const size_t t = std::min(size_t(std::upper_bound(cdf.begin(), cdf.end(), rng.next_double() * acc) - cdf.begin()), tris - 1);
    const glm::dvec3 p0 = mesh.positions[mesh.indices[3 * t]], p1 = mesh.positions[mesh.indices[3 * t + 1]],
                     p2 = mesh.positions[mesh.indices[3 * t + 2]];
    glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
    if (!(glm::length(n) > 0)) continue;
    n = glm::normalize(n);
    double u = rng.next_double(), v = rng.next_double();
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const glm::dvec3 p = p0 + u * (p1 - p0) + v * (p2 - p0);
    const double eps = 1e-5 * std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z), 1e-2});
    for (double side : {1.0, -1.0}) {
      const RayHit h = e.intersect(p + side * eps * n, side * n, float(limit_m));
      if (h.found() && h.geom == geom) {
        ++thin;
        break;
      }
    }
  }
  return double(thin) / kThicknessSamples;
}

}  // namespace

std::vector<std::string> spatial_geometry_warnings(const Scene& sc, const EmbreeScene& e, const RenderTables& t) {
  std::vector<std::string> out;
  int used = 0;
  for (int i = 0; i < t.n; ++i)
    if (t.wavelength_pdf.pmf[i] > 0) used = i + 1;
  for (unsigned g = 0; g < e.geometries(); ++g) {
    const GeomInfo& gi = e.info(g);
    if (gi.kind != GeomInfo::Kind::kMesh) continue;
    const std::vector<int> members = spatial_members(sc, t, gi.material);
    if (members.empty()) continue;
    const TriangleMesh& mesh = sc.meshes[gi.index];
    const std::string what = "material \"" + sc.materials[gi.material].name + "\" on mesh \"" + mesh.name + "\"";
    char buf[400];
    if (double bad = inconsistent_edges(mesh); bad > 0) {
      std::snprintf(buf, sizeof buf,
                    "%s: %.1f %% of its edges are wound inconsistently; the spatial transport cannot tell the near side from "
                    "the far side there and light travelling sideways across them is lost",
                    what.c_str(), 100.0 * bad);
      out.push_back(buf);
    }
    double r90 = 0;
    for (int m : members) r90 = std::max(r90, r90_mm(*t.materials[m].stack.spatial, used));
    if (!(r90 > 0)) continue;
    if (double share = thin_share(e, g, mesh, r90 / 1000.0); share > kThinShare) {
      std::snprintf(buf, sizeof buf,
                    "%s: %.0f %% of its area is thinner than %.2f mm, the radius holding 90 %% of the light that travels sideways "
                    "in it; the layers are taken as semi-infinite there, so light that would reach the far surface stays on the near one",
                    what.c_str(), 100.0 * share, r90);
      out.push_back(buf);
    }
  }
  return out;
}

}  // namespace ofl
