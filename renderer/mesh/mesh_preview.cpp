#include "renderer/mesh/mesh_preview.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/geometric.hpp>

#include "renderer/core/errors/error.h"
#include "renderer/image/image_file.h"
#include "renderer/mesh/files/gltf_writer.h"
#include "renderer/mesh/geometry/raster_triangle.h"

namespace ofl {


PreviewCamera named_view(const std::string& name) {
  PreviewCamera c;
  if (name == "front") c.eye = {1, 0, 0};
  else if (name == "side") c.eye = {0, -1, 0};
  else if (name == "top") { c.eye = {0, 0, 1}; c.up = {-1, 0, 0}; }
  else if (name == "iso") c.eye = {1, -0.8, 0.6};
  else if (name == "camera") {
    c.perspective = true;
    c.eye = {0.05, 0, 0.0};
    c.target = {-0.03, 0, -0.004};
    c.fov_deg = 60;
  } else {
    throw InputError("command line", "--view", "unknown view '" + name + "' (front, side, top, iso, camera)");
  }
  return c;
}

ClipPlane parse_clip(const std::string& s) {
  ClipPlane c;
  if (s.empty()) return c;
  if (s.size() < 3 || s[0] < 'x' || s[0] > 'z' || (s[1] != '<' && s[1] != '>'))
    throw InputError("command line", "--clip", "expected AXIS<VALUE or AXIS>VALUE, e.g. y<0, found '" + s + "'");
  c.axis = s[0] - 'x';
  c.keep_below = s[1] == '<';
  try {
    size_t used = 0;
    c.value = std::stod(s.substr(2), &used);
    if (used != s.size() - 2) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    throw InputError("command line", "--clip", "not a number after the comparison in '" + s + "'");
  }
  return c;
}

double UvOverlay::sample(double u, double v) const {
  if (width <= 0 || height <= 0) return 0;
  double x = std::clamp(u * width - 0.5, 0.0, width - 1.0), y = std::clamp(v * height - 0.5, 0.0, height - 1.0);
  int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  double fx = x - x0, fy = y - y0;
  auto at = [&](int xx, int yy) { return static_cast<double>(value[static_cast<size_t>(yy) * width + xx]); };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
}

UvOverlay read_overlay(const std::string& file) {
  FloatImage im = read_image_file(file);
  UvOverlay o;
  o.width = im.width;
  o.height = im.height;
  o.value.resize(static_cast<size_t>(o.width) * o.height);
  for (size_t i = 0; i < o.value.size(); ++i) o.value[i] = im.pixels[i * im.channels];
  return o;
}

std::pair<std::string, UvOverlay> parse_overlay(const std::string& spec) {
  auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("command line", "--overlay", "expected MATERIAL=file.png[@R,G,B], found '" + spec + "'");
  std::string file = spec.substr(eq + 1);
  glm::dvec3 color(0.1, 0.9, 0.2);
  if (auto at = file.rfind('@'); at != std::string::npos) {
    std::string c = file.substr(at + 1);
    file = file.substr(0, at);
    if (std::sscanf(c.c_str(), "%lf,%lf,%lf", &color.x, &color.y, &color.z) != 3)
      throw InputError("command line", "--overlay", "colour must be R,G,B in 0..1, found '" + c + "'");
  }
  UvOverlay o = read_overlay(file);
  o.color = color;
  return {spec.substr(0, eq), std::move(o)};
}

namespace {

// Camera space to pixels: perspective, or orthographic fitted to the projected vertices (centre and
// height) unless the camera gives its height.
struct PreviewProjection {
  const PreviewCamera& cam;
  int W = 0, H = 0;
  double aspect = 1, tan_half = 1, half_h = 1;
  glm::dvec3 f{0, 0, 1}, r{1, 0, 0}, u{0, 1, 0};
  glm::dvec2 center{0.0};
  static constexpr double kNear = 1e-4;

  PreviewProjection(const std::vector<TriangleMesh>& meshes, const PreviewCamera& c, const PreviewOptions& opt)
      : cam(c), W(opt.width), H(opt.height) {
    aspect = static_cast<double>(W) / H;
    f = glm::normalize(cam.target - cam.eye);
    r = glm::normalize(glm::cross(f, cam.up));
    u = glm::cross(r, f);
    if (!cam.perspective) fit_orthographic(meshes, opt);
    tan_half = std::tan(0.5 * cam.fov_deg * 3.14159265358979 / 180.0);
  }

  void fit_orthographic(const std::vector<TriangleMesh>& meshes, const PreviewOptions& opt) {
    glm::dvec2 lo(1e300), hi(-1e300);
    for (auto& m : meshes)
      for (auto& p : m.positions) {
        glm::dvec3 d = glm::dvec3(p) - cam.eye;
        if (opt.clip.axis >= 0) {
          double c = p[opt.clip.axis];
          if (opt.clip.keep_below ? c > opt.clip.value : c < opt.clip.value) continue;
        }
        glm::dvec2 q(glm::dot(d, r), glm::dot(d, u));
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
      }
    if (lo.x > hi.x) lo = hi = glm::dvec2(0.0);
    center = 0.5 * (lo + hi);
    half_h = cam.ortho_height > 0 ? 0.5 * cam.ortho_height : 0.54 * std::max(hi.y - lo.y, (hi.x - lo.x) / aspect);
    if (!(half_h > 0)) half_h = 1;
  }

  struct Projected {
    double x, y, z;  // pixel coordinates and camera depth
  };
  bool project(const glm::dvec3& p, Projected& out) const {
    glm::dvec3 d = p - cam.eye;
    double cx = glm::dot(d, r), cy = glm::dot(d, u), cz = glm::dot(d, f);
    double nx, ny;
    if (cam.perspective) {
      if (cz < kNear) return false;
      nx = cx / (cz * tan_half * aspect);
      ny = cy / (cz * tan_half);
    } else {
      nx = (cx - center.x) / (half_h * aspect);
      ny = (cy - center.y) / half_h;
    }
    out = {(nx * 0.5 + 0.5) * W, (0.5 - ny * 0.5) * H, cz};
    return true;
  }
};

// The colour of a mesh point seen along `view`: the material's hint colour under its UV overlays,
// shaded by the normal's cosine to the viewer, tinted blue where the back of the face is seen.
glm::dvec3 preview_colour(glm::dvec3 base, const std::vector<const UvOverlay*>& overlays, const glm::dvec2& uv,
                          const glm::dvec3& n, const glm::dvec3& view, bool front) {
  glm::dvec3 col = base;
  for (const UvOverlay* o : overlays) {
    double a = std::clamp(o->sample(uv.x, uv.y), 0.0, 1.0);
    col = (1 - a) * col + a * o->color;
  }
  double shade = 0.12 + 0.88 * std::abs(glm::dot(n, view));
  if (!front) col = 0.5 * (0.4 * col + glm::dvec3(0.1, 0.2, 0.6));
  return col * shade;
}

}  // namespace

std::vector<float> render_preview(const std::vector<TriangleMesh>& meshes, PreviewCamera cam, const PreviewOptions& opt) {
  const int W = opt.width, H = opt.height;
  const PreviewProjection proj(meshes, cam, opt);
  std::vector<float> rgb(static_cast<size_t>(W) * H * 3);
  for (size_t i = 0; i < rgb.size(); i += 3) {
    rgb[i] = static_cast<float>(opt.background.x);
    rgb[i + 1] = static_cast<float>(opt.background.y);
    rgb[i + 2] = static_cast<float>(opt.background.z);
  }
  std::vector<double> depth(static_cast<size_t>(W) * H, std::numeric_limits<double>::infinity());
  for (const auto& m : meshes) {
    glm::dvec3 base = material_hint_color(m.material);
    std::vector<const UvOverlay*> overlays;
    for (const auto& [material, o] : opt.overlays)
      if (material == m.material && !m.uvs.empty()) overlays.push_back(&o);
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      uint32_t id[3] = {m.indices[t], m.indices[t + 1], m.indices[t + 2]};
      glm::dvec3 P[3] = {glm::dvec3(m.positions[id[0]]), glm::dvec3(m.positions[id[1]]), glm::dvec3(m.positions[id[2]])};
      PreviewProjection::Projected s[3];
      if (!proj.project(P[0], s[0]) || !proj.project(P[1], s[1]) || !proj.project(P[2], s[2])) continue;
      glm::dvec3 ng = glm::cross(P[1] - P[0], P[2] - P[0]);
      auto shade_pixel = [&](int px, int py, double l0, double l1, double l2) {
        double w0 = l0, w1 = l1, w2 = l2;
        if (cam.perspective) {  // perspective-correct weights
          w0 /= s[0].z; w1 /= s[1].z; w2 /= s[2].z;
          double sum = w0 + w1 + w2;
          w0 /= sum; w1 /= sum; w2 /= sum;
        }
        double z = w0 * s[0].z + w1 * s[1].z + w2 * s[2].z;
        size_t pix = static_cast<size_t>(py) * W + px;
        if (z >= depth[pix]) return;
        glm::dvec3 wp = w0 * P[0] + w1 * P[1] + w2 * P[2];
        if (opt.clip.axis >= 0) {
          double c = wp[opt.clip.axis];
          if (opt.clip.keep_below ? c > opt.clip.value : c < opt.clip.value) return;
        }
        depth[pix] = z;
        glm::dvec3 view = cam.perspective ? glm::normalize(cam.eye - wp) : -proj.f;
        glm::dvec3 n = ng;
        if (!m.normals.empty())
          n = w0 * glm::dvec3(m.normals[id[0]]) + w1 * glm::dvec3(m.normals[id[1]]) + w2 * glm::dvec3(m.normals[id[2]]);
        double nl = glm::length(n);
        n = nl > 0 ? n / nl : glm::normalize(ng);
        glm::dvec2 uv(0.0);
        if (!overlays.empty()) uv = w0 * glm::dvec2(m.uvs[id[0]]) + w1 * glm::dvec2(m.uvs[id[1]]) + w2 * glm::dvec2(m.uvs[id[2]]);
        const glm::dvec3 col = preview_colour(base, overlays, uv, n, view, glm::dot(ng, view) > 0);
        rgb[pix * 3] = static_cast<float>(col.x);
        rgb[pix * 3 + 1] = static_cast<float>(col.y);
        rgb[pix * 3 + 2] = static_cast<float>(col.z);
      };
      raster_triangle({s[0].x, s[0].y}, {s[1].x, s[1].y}, {s[2].x, s[2].y}, W, H, shade_pixel, 1e-12);
    }
  }
  return rgb;
}

}  // namespace ofl
