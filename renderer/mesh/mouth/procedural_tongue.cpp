#include "renderer/mesh/mouth/procedural_tongue.h"

#include <algorithm>
#include <cmath>

#include "renderer/mesh/geometry/mesh_measure.h"

namespace ofl {
namespace {
constexpr double kPi = 3.14159265358979323846;
double spow(double v, double e) { return std::copysign(std::pow(std::abs(v), e), v); }
}  // namespace

TongueShape tongue_shape(const MouthParams& p) {
  TongueShape s;
  s.a = p.tongue_length_m / 2;
  s.b = p.tongue_width_m / 2;
  s.c_top = p.tongue_thickness_m * p.tongue_dorsum_fraction;
  s.c_bottom = p.tongue_thickness_m * (1 - p.tongue_dorsum_fraction);
  return s;
}

TriangleMesh make_procedural_tongue(const MouthParams& p) {
  const TongueShape s = tongue_shape(p);
  const int nu = std::max(16, p.segments / 2);  // around
  const int nv = std::max(16, p.segments / 2);  // tip to back
  TriangleMesh m;
  m.name = "tongue";
  m.material = "tongue";
  const double pitch = p.tongue_pitch_deg * kPi / 180;
  // Grid (nv+1) x (nu+1): row 0 is the tip pole, row nv the back pole; column nu repeats column 0
  // (same positions, u = 1) so the UV seam on the underside has its own vertices.
  for (int i = 0; i <= nv; ++i) {
    double alpha = kPi * i / nv;          // 0 at the tip
    double x = s.a * spow(std::cos(alpha), 2 / s.p);
    double ring = std::pow(std::abs(std::sin(alpha)), 1.0);  // |sin|, raised below per axis
    double uu = x / s.a;                   // +1 tip, -1 back
    for (int j = 0; j <= nu; ++j) {
      double beta = -kPi / 2 + 2 * kPi * j / nu;  // -pi/2 underside, +pi/2 dorsum
      double cb = std::cos(beta), sb = std::sin(beta);
      double y = s.b * std::pow(ring, 2 / s.q) * spow(cb, 2 / s.q);
      double c = sb >= 0 ? s.c_top : s.c_bottom;
      double z = c * std::pow(ring, 2 / s.r) * spow(sb, 2 / s.r);
      if (i == 0 || i == nv) y = z = 0;      // exact poles
      y *= 1 - p.tongue_taper * uu;          // narrower tip, wider back (volume-preserving)
      z -= (uu > 0 ? p.tongue_tip_droop_m : p.tongue_back_droop_m) * uu * uu;  // droop (a shear)
      // Pitch about y (positive: tip down), then place.
      double xr = std::cos(pitch) * x + std::sin(pitch) * z;
      double zr = -std::sin(pitch) * x + std::cos(pitch) * z;
      m.positions.push_back(glm::vec3(static_cast<float>(xr), static_cast<float>(y), static_cast<float>(zr)));
      m.uvs.push_back(glm::vec2(static_cast<float>(static_cast<double>(j) / nu), static_cast<float>(static_cast<double>(i) / nv)));
    }
  }
  // Make the seam column bit-identical to column 0.
  for (int i = 0; i <= nv; ++i) m.positions[static_cast<size_t>(i) * (nu + 1) + nu] = m.positions[static_cast<size_t>(i) * (nu + 1)];
  auto id = [&](int i, int j) { return static_cast<uint32_t>(i * (nu + 1) + j); };
  for (int i = 0; i < nv; ++i)
    for (int j = 0; j < nu; ++j) {
      uint32_t a = id(i, j), b = id(i, j + 1), c = id(i + 1, j), d = id(i + 1, j + 1);
      if (i > 0) m.indices.insert(m.indices.end(), {a, c, b});
      if (i + 1 < nv) m.indices.insert(m.indices.end(), {b, c, d});
    }
  // Orientation: outward normals give a positive volume.
  if (enclosed_volume(m) < 0)
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) std::swap(m.indices[t + 1], m.indices[t + 2]);
  // Place: the tip (largest x) at tongue_protrusion_m, mid-plane height at mid-length.
  double tip = -1e300;
  for (auto& v : m.positions) tip = std::max(tip, static_cast<double>(v.x));
  translate_mesh(m, glm::dvec3(p.tongue_protrusion_m - tip, 0.0, p.tongue_center_z_m));
  compute_smooth_normals(m);
  return m;
}

}  // namespace ofl
