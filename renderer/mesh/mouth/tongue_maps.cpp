#include "renderer/mesh/mouth/tongue_maps.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <glm/geometric.hpp>

#include "renderer/core/errors/error.h"
#include "renderer/image/image_file.h"
#include "renderer/mesh/geometry/mesh_measure.h"
#include "renderer/mesh/geometry/raster_triangle.h"

namespace ofl {
namespace {

double smoothstep(double a, double b, double x) {
  double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// Calls f(texel x, texel y, position, normal) for every texel centre inside a UV triangle.
void rasterise_uv(const TriangleMesh& m, int size,
                  const std::function<void(int, int, const glm::dvec3&, const glm::dvec3&)>& f) {
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    uint32_t id[3] = {m.indices[t], m.indices[t + 1], m.indices[t + 2]};
    glm::dvec2 q[3];
    for (int k = 0; k < 3; ++k) q[k] = glm::dvec2(m.uvs[id[k]]) * static_cast<double>(size);
    raster_triangle(q[0], q[1], q[2], size, size, [&](int px, int py, double l0, double l1, double l2) {
      glm::dvec3 pos = l0 * glm::dvec3(m.positions[id[0]]) + l1 * glm::dvec3(m.positions[id[1]]) +
                       l2 * glm::dvec3(m.positions[id[2]]);
      glm::dvec3 n = l0 * glm::dvec3(m.normals[id[0]]) + l1 * glm::dvec3(m.normals[id[1]]) +
                     l2 * glm::dvec3(m.normals[id[2]]);
      double len = glm::length(n);
      f(px, py, pos, len > 0 ? n / len : glm::dvec3(0, 0, 1));
    });
  }
}

void dilate(UvMap& map, int steps) {
  std::vector<uint8_t> filled = map.covered;
  const int s = map.size;
  for (int it = 0; it < steps; ++it) {
    std::vector<uint8_t> next = filled;
    std::vector<float> val = map.value;
    for (int y = 0; y < s; ++y)
      for (int x = 0; x < s; ++x) {
        size_t i = static_cast<size_t>(y) * s + x;
        if (filled[i]) continue;
        double sum = 0;
        int cnt = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= s || yy >= s) continue;
            size_t j = static_cast<size_t>(yy) * s + xx;
            if (filled[j]) { sum += map.value[j]; ++cnt; }
          }
        if (cnt) { val[i] = static_cast<float>(sum / cnt); next[i] = 1; }
      }
    map.value.swap(val);
    filled.swap(next);
  }
}

// Value-weighted UV centroid and the UV box where the value exceeds half its maximum.
nlohmann::json uv_summary(const UvMap& m) {
  double sw = 0, su = 0, sv = 0, peak = 0;
  for (int y = 0; y < m.size; ++y)
    for (int x = 0; x < m.size; ++x)
      if (m.covered[static_cast<size_t>(y) * m.size + x]) peak = std::max(peak, static_cast<double>(m.at(x, y)));
  glm::dvec2 lo(1e9), hi(-1e9);
  size_t texels = 0;
  for (int y = 0; y < m.size; ++y)
    for (int x = 0; x < m.size; ++x) {
      size_t i = static_cast<size_t>(y) * m.size + x;
      if (!m.covered[i]) continue;
      double w = m.value[i];
      glm::dvec2 uv((x + 0.5) / m.size, (y + 0.5) / m.size);
      sw += w; su += w * uv.x; sv += w * uv.y;
      if (peak > 0 && w > 0.5 * peak) { lo = glm::min(lo, uv); hi = glm::max(hi, uv); ++texels; }
    }
  nlohmann::json j = {{"peak", peak}, {"texels_above_half", texels}};
  if (sw > 0) j["uv_centroid"] = {su / sw, sv / sw};
  if (texels) j["uv_box_above_half"] = {{lo.x, lo.y}, {hi.x, hi.y}};
  return j;
}

}  // namespace

TongueMaps make_tongue_maps(const std::vector<TriangleMesh>& tongue, const TongueMapParams& p) {
  if (p.size < 16 || p.size > 8192) throw InputError("command line", "--size", "must be in [16, 8192]");
  TriangleMesh m;
  for (const auto& part : tongue) {
    if (part.uvs.empty()) throw InputError(part.name, "TEXCOORD_0", "the tongue mesh has no UVs");
    TriangleMesh c = part;
    if (c.normals.empty()) compute_smooth_normals(c);
    append_mesh(m, c);
  }
  if (m.indices.empty()) throw InputError("tongue", "", "no tongue triangles (material 'tongue')");

  // The tongue's frame, read off the mesh.
  Bounds b = mesh_bounds(m);
  const double x_tip = b.max.x, x_back = b.min.x, length = x_tip - x_back, y_mid = b.center().y;
  const double xp = x_tip - p.porphyrin_center_frac * length;
  const double xl = x_tip - p.lesion_center_frac * length;
  glm::dvec3 lesion_center(xl, y_mid, 0);
  double best = -1e300;
  for (auto& v : m.positions)
    if (std::abs(v.x - xl) < 0.05 * length && p.lesion_side * v.y > best) {
      best = p.lesion_side * v.y;
      lesion_center = glm::dvec3(v);
    }

  TongueMaps out;
  for (UvMap* map : {&out.porphyrin, &out.lesion, &out.dorsal}) {
    map->size = p.size;
    map->value.assign(static_cast<size_t>(p.size) * p.size, 0.0f);
    map->covered.assign(static_cast<size_t>(p.size) * p.size, 0);
  }
  rasterise_uv(m, p.size, [&](int x, int y, const glm::dvec3& pos, const glm::dvec3& n) {
    size_t i = static_cast<size_t>(y) * p.size + x;
    double dorsal = smoothstep(0.15, 0.5, n.z);
    double rx = (pos.x - xp) / p.porphyrin_radius_x_m, ry = (pos.y - y_mid) / p.porphyrin_radius_y_m;
    double r2 = rx * rx + ry * ry;
    double d = glm::length(pos - lesion_center) / p.lesion_radius_m;
    out.porphyrin.value[i] = static_cast<float>(dorsal * std::exp(-r2 * r2));
    out.lesion.value[i] = static_cast<float>(std::exp(-d * d * d * d));
    out.dorsal.value[i] = static_cast<float>(dorsal);
    out.porphyrin.covered[i] = out.lesion.covered[i] = out.dorsal.covered[i] = 1;
  });

  // Where the tip and back land in UV space (vertices with the largest / smallest x).
  size_t tip = 0, back = 0;
  for (size_t i = 0; i < m.positions.size(); ++i) {
    if (m.positions[i].x > m.positions[tip].x) tip = i;
    if (m.positions[i].x < m.positions[back].x) back = i;
  }
  size_t covered = 0;
  for (auto c : out.porphyrin.covered) covered += c;
  out.report = {
      {"tongue_frame", {{"x_tip_m", x_tip}, {"x_back_m", x_back}, {"length_m", length}, {"y_mid_m", y_mid},
                        {"width_m", b.size().y}}},
      {"uv_coverage", static_cast<double>(covered) / (static_cast<double>(p.size) * p.size)},
      {"tip_uv", {m.uvs[tip].x, m.uvs[tip].y}},
      {"back_uv", {m.uvs[back].x, m.uvs[back].y}},
      {"dorsal", uv_summary(out.dorsal)},
      {"porphyrin", uv_summary(out.porphyrin)},
      {"lesion", uv_summary(out.lesion)},
  };
  out.report["porphyrin"]["center_m"] = {xp, y_mid};
  out.report["lesion"]["center_m"] = {lesion_center.x, lesion_center.y, lesion_center.z};
  for (UvMap* map : {&out.porphyrin, &out.lesion, &out.dorsal}) dilate(*map, p.dilate_texels);
  return out;
}

void write_gray16_png(const std::filesystem::path& file, const UvMap& map) {
  std::vector<uint16_t> px(map.value.size());
  for (size_t i = 0; i < px.size(); ++i)
    px[i] = static_cast<uint16_t>(std::lround(65535.0 * std::clamp(static_cast<double>(map.value[i]), 0.0, 1.0)));
  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  write_image_file(file, OIIO::ImageSpec(map.size, map.size, 1, OIIO::TypeDesc::UINT16), px.data());
}

void write_uv_layout_png(const std::filesystem::path& file, const TongueMaps& maps) {
  const int s = maps.porphyrin.size;
  std::vector<uint8_t> px(static_cast<size_t>(s) * s * 3);
  for (size_t i = 0; i < static_cast<size_t>(s) * s; ++i) {
    double grey = maps.porphyrin.covered[i] ? 0.35 : 0.05;
    double r = grey, g = grey, bl = grey + 0.4 * maps.dorsal.value[i] * maps.porphyrin.covered[i];
    double por = maps.porphyrin.value[i], les = maps.lesion.value[i];
    r = r * (1 - por) + por;
    g = g * (1 - les) + les;
    px[i * 3] = static_cast<uint8_t>(std::lround(255 * std::clamp(r, 0.0, 1.0)));
    px[i * 3 + 1] = static_cast<uint8_t>(std::lround(255 * std::clamp(g, 0.0, 1.0)));
    px[i * 3 + 2] = static_cast<uint8_t>(std::lround(255 * std::clamp(bl, 0.0, 1.0)));
  }
  write_image_file(file, OIIO::ImageSpec(s, s, 3, OIIO::TypeDesc::UINT8), px.data());
}

}  // namespace ofl
