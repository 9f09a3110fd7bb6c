#include "renderer/mesh/mouth/mouth_generator.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "renderer/mesh/geometry/mesh_measure.h"
#include "renderer/mesh/mouth/procedural_tongue.h"

namespace ofl {
namespace {

constexpr double kPi = 3.14159265358979323846;
double spow(double v, double e) { return std::copysign(std::pow(std::abs(v), e), v); }
double smoothstep(double t) { return t * t * (3 - 2 * t); }

// Vertex rings, one point per column; all rings share the column angles
// theta_j = -pi/4 + 2 pi j / N (0 = +y, the patient's left; pi/2 = up).
using Ring = std::vector<glm::dvec3>;

struct Builder {
  const MouthParams& p;
  int n;
  double r, x_cavity, x_back;

  explicit Builder(const MouthParams& params)
      : p(params), n(params.segments), r(params.lip_thickness_m / 2),
        x_cavity(-(params.lip_thickness_m / 2 + params.vestibule_depth_m)), x_back(-params.cavity_depth_m) {}

  double theta(int j) const { return -kPi / 4 + 2 * kPi * j / n; }

  // Superellipse point with half-axes (a, b) and exponent e at angle t.
  static glm::dvec2 superellipse(double a, double b, double e, double t) {
    return {a * spow(std::cos(t), 2 / e), b * spow(std::sin(t), 2 / e)};
  }

  // Lip tube radius at angle t: full at the midline, thinner towards the corners.
  double lip_radius(double t) const {
    return r * (p.lip_commissure_ratio + (1 - p.lip_commissure_ratio) * std::abs(std::sin(t)));
  }

  // The lip tube: opening point O, outward normal of the opening in the y-z plane, centre x.
  void lip_frame(double t, glm::dvec2& o, glm::dvec2& normal, double& x) const {
    const double a = p.opening_width_m / 2, b = p.opening_m / 2, e = p.opening_exponent;
    o = superellipse(a, b, e, t);
    glm::dvec2 g(spow(o.x / a, e - 1) / a, spow(o.y / b, e - 1) / b);
    normal = glm::length(g) > 0 ? glm::normalize(g) : glm::dvec2(std::cos(t), std::sin(t));
    double low = std::max(0.0, -std::sin(t));
    x = -p.lower_lip_setback_m * low * low;
  }

  // A point on the lip tube at roll angle phi: 0 = facing outwards (radially), pi/2 = front,
  // pi = the inner edge (the opening), 3 pi/2 = facing back into the mouth.
  Ring lip_ring(double phi) const {
    Ring ring(n);
    for (int j = 0; j < n; ++j) {
      glm::dvec2 o, nrm;
      double x;
      lip_frame(theta(j), o, nrm, x);
      const double rt = lip_radius(theta(j));
      glm::dvec2 c = o + rt * nrm;
      glm::dvec2 yz = c + rt * std::cos(phi) * nrm;
      ring[j] = {x + rt * std::sin(phi), yz.x, yz.y};
    }
    return ring;
  }

  double floor_z(double x) const {
    double t = (x_cavity - x) / (x_cavity - x_back);
    return -p.floor_depth_m + p.floor_rise_m * std::clamp(t, 0.0, 1.0);
  }
  double center_z(double x) const { return 0.5 * (p.palate_height_m + floor_z(x)); }

  // Cavity cross-section at depth x (x_back <= x <= x_cavity), scaled about its centre by s.
  Ring cavity_ring(double x, double s = 1.0) const {
    Ring ring(n);
    const double w = p.cavity_width_m / 2, zc = center_z(x), h = 0.5 * (p.palate_height_m - floor_z(x));
    for (int j = 0; j < n; ++j) {
      double t = theta(j);
      glm::dvec2 q = superellipse(w, h, p.cavity_exponent, t);
      if (std::sin(t) > 0) {
        double u = q.x / (0.7 * w);
        if (std::abs(u) < 1) q.y += p.palate_vault_m * (1 - u * u) * (1 - u * u);
      }
      ring[j] = {x, s * q.x, zc + s * q.y};
    }
    return ring;
  }

  Ring outer_ring(double x, double s = 1.0) const {
    Ring ring(n);
    for (int j = 0; j < n; ++j) {
      glm::dvec2 q = superellipse(p.face_width_m / 2, p.face_height_m / 2, 4.0, theta(j));
      ring[j] = {x, s * q.x, s * q.y};
    }
    return ring;
  }
};

struct Region {
  const char* name;
  const char* material;
  int row0, row1;  // inclusive vertex rows
  int col0, cols;  // first column and number of quads across (columns wrap)
};

// The rings of the whole solid from the back of the head to the pharynx, and the rows where its
// regions begin and end.
struct Sections {
  std::vector<Ring> rows;
  int skin_row0 = 0, lip_row0 = 0, cavity_row0 = 0, last_row = 0;
};

Sections section_rows(const Builder& b, const MouthParams& p) {
  const int n = p.segments;
  Sections s;
  std::vector<Ring>& rows = s.rows;
  // 1. Back of the head block: a flat cap from the pole outwards, then the sides.
  const double xh = -p.head_depth_m, xf = -p.face_recess_m;
  for (int k = 0; k <= 4; ++k) rows.push_back(b.outer_ring(xh, k / 4.0));
  for (int k = 1; k <= 4; ++k) rows.push_back(b.outer_ring(xh + (xf - xh) * k / 4.0));
  s.skin_row0 = 0;
  // 2. Face plate: from the outer edge to the lip tube (entered at phi0, behind its outer side).
  const double phi0 = -kPi / 4;
  const Ring outer = b.outer_ring(xf), lip_start = b.lip_ring(phi0);
  for (int k = 1; k <= 12; ++k) {
    double t = k / 12.0;
    Ring ring(n);
    for (int j = 0; j < n; ++j) {
      glm::dvec3 q = (1 - t) * outer[j] + t * lip_start[j];
      q.x = outer[j].x + (lip_start[j].x - outer[j].x) * t * t;
      ring[j] = q;
    }
    rows.push_back(ring);
  }
  s.lip_row0 = static_cast<int>(rows.size()) - 1;
  // 3. Lip tube from phi0 to 3 pi/2 in steps of pi/16 (so phi = pi, the opening, is a row).
  const int lip_steps = 28;
  for (int k = 1; k <= lip_steps; ++k) rows.push_back(b.lip_ring(phi0 + (1.5 * kPi - phi0) * k / lip_steps));
  s.cavity_row0 = static_cast<int>(rows.size()) - 1;
  // 4. Vestibule: blend from the back of the lips to the first full cavity section.
  const Ring lip_back = rows.back(), cav_front = b.cavity_ring(b.x_cavity);
  const int vest_steps = 12;
  for (int k = 1; k <= vest_steps; ++k) {
    double t = static_cast<double>(k) / vest_steps, st = smoothstep(t);
    Ring ring(n);
    for (int j = 0; j < n; ++j) {
      glm::dvec3 q = (1 - st) * lip_back[j] + st * cav_front[j];
      q.x = lip_back[j].x + (cav_front[j].x - lip_back[j].x) * t;
      ring[j] = q;
    }
    rows.push_back(ring);
  }
  // 5. The cavity, then the flat pharynx wall closing at its centre.
  const int cav_steps = 40;
  for (int k = 1; k <= cav_steps; ++k) rows.push_back(b.cavity_ring(b.x_cavity + (b.x_back - b.x_cavity) * k / cav_steps));
  for (int k = 1; k <= 8; ++k) rows.push_back(b.cavity_ring(b.x_back, 1 - k / 8.0));
  s.last_row = static_cast<int>(rows.size()) - 1;
  return s;
}

// The two triangles of the quad (a, b, c, d), skipping any with two equal corners (at the poles).
void add_quad(std::vector<uint32_t>& out, uint32_t a, uint32_t bb, uint32_t c, uint32_t d, bool flip,
              const std::vector<glm::vec3>& P) {
  uint32_t t1[3] = {a, c, bb}, t2[3] = {bb, c, d};
  for (auto* t : {t1, t2}) {
    if (P[t[0]] == P[t[1]] || P[t[1]] == P[t[2]] || P[t[0]] == P[t[2]]) continue;
    if (flip) out.insert(out.end(), {t[0], t[2], t[1]});
    else out.insert(out.end(), {t[0], t[1], t[2]});
  }
}

// One welded mesh of the whole solid (float positions; the poles are exact single points): it
// fixes the orientation (`flip`: the rows wind inward) and gives smooth normals.
TriangleMesh whole_solid(const Sections& s, int n, bool& flip) {
  TriangleMesh whole;
  whole.positions.resize(s.rows.size() * n);
  for (size_t i = 0; i < s.rows.size(); ++i)
    for (int j = 0; j < n; ++j) whole.positions[i * n + j] = glm::vec3(s.rows[i][j]);
  for (int i = 0; i < s.last_row; ++i)
    for (int j = 0; j < n; ++j) {
      int j1 = (j + 1) % n;
      add_quad(whole.indices, i * n + j, i * n + j1, (i + 1) * n + j, (i + 1) * n + j1, false, whole.positions);
    }
  flip = enclosed_volume(whole) < 0;
  if (flip) flip_mesh(whole);
  compute_smooth_normals(whole);
  return whole;
}

// A region of the whole solid as its own mesh, with the solid's normals and UVs over its grid.
TriangleMesh region_mesh(const TriangleMesh& whole, const Region& reg, int n, bool flip) {
  TriangleMesh m;
  m.name = reg.name;
  m.material = reg.material;
  const int nr = reg.row1 - reg.row0 + 1, nc = reg.cols + 1;
  for (int i = 0; i < nr; ++i)
    for (int c = 0; c < nc; ++c) {
      size_t g = static_cast<size_t>(reg.row0 + i) * n + (reg.col0 + c) % n;
      m.positions.push_back(whole.positions[g]);
      m.normals.push_back(whole.normals[g]);
      m.uvs.push_back(glm::vec2(static_cast<float>(static_cast<double>(c) / reg.cols),
                                static_cast<float>(static_cast<double>(i) / (nr - 1))));
    }
  for (int i = 0; i + 1 < nr; ++i)
    for (int c = 0; c < reg.cols; ++c)
      add_quad(m.indices, i * nc + c, i * nc + c + 1, (i + 1) * nc + c, (i + 1) * nc + c + 1, flip, m.positions);
  return m;
}

// The named points other parts are placed at, and the procedural tongue with its tip and dorsum.
void add_anchors_and_tongue(Mouth& mouth, const Builder& b, const MouthParams& p) {
  const MouthParams defaults;
  mouth.anchors.push_back({"opening_center", glm::dvec3(0.0)});
  mouth.anchors.push_back({"upper_teeth_slot", {0, 0, p.palate_height_m - defaults.palate_height_m}});
  mouth.anchors.push_back({"lower_teeth_slot", {0, 0, defaults.floor_depth_m - p.floor_depth_m}});
  mouth.anchors.push_back({"sofa_tongue_slot", {0, 0, defaults.floor_depth_m - p.floor_depth_m}});
  mouth.anchors.push_back({"pharynx_center", {b.x_back, 0, b.center_z(b.x_back)}});
  if (!p.tongue) return;
  TriangleMesh t = make_procedural_tongue(p);
  glm::vec3 tip = t.positions[0], top = t.positions[0];
  for (auto& v : t.positions) {
    if (v.x > tip.x) tip = v;
    if (v.z > top.z) top = v;
  }
  mouth.anchors.push_back({"tongue_tip", glm::dvec3(tip)});
  mouth.anchors.push_back({"tongue_dorsum", glm::dvec3(top)});
  mouth.parts.push_back(std::move(t));
}

}  // namespace

Mouth make_mouth(const MouthParams& p) {
  validate_mouth_params(p, "mouth parameters");
  Builder b(p);
  const int n = p.segments;
  const Sections s = section_rows(b, p);
  bool flip = false;
  const TriangleMesh whole = whole_solid(s, n, flip);
  const int q = n / 8;
  const Region regions[] = {
      {"skin", "skin", s.skin_row0, s.lip_row0, 0, n},
      {"upper_lip", "lips", s.lip_row0, s.cavity_row0, q, 4 * q},
      {"lower_lip", "lips", s.lip_row0, s.cavity_row0, 5 * q, 4 * q},
      {"cheek_left", "cheek", s.cavity_row0, s.last_row, 0, 2 * q},
      {"palate", "palate", s.cavity_row0, s.last_row, 2 * q, 2 * q},
      {"cheek_right", "cheek", s.cavity_row0, s.last_row, 4 * q, 2 * q},
      {"floor", "floor", s.cavity_row0, s.last_row, 6 * q, 2 * q},
  };
  Mouth mouth;
  for (const auto& reg : regions) mouth.parts.push_back(region_mesh(whole, reg, n, flip));
  add_anchors_and_tongue(mouth, b, p);
  return mouth;
}

GlbDocument mouth_document(const MouthParams& p) {
  Mouth m = make_mouth(p);
  GlbDocument doc;
  doc.meshes = std::move(m.parts);
  doc.anchors = std::move(m.anchors);
  doc.generator = "oralfluor mesh mouth";
  doc.extras = {{"mouth_params", to_json(p)},
                {"frame", "origin at the centre of the lip opening, +x out of the mouth, +z up, +y patient's left; metres"}};
  return doc;
}

}  // namespace ofl
