// Reads a scene file into a Scene. Sections: "format"/"version", "integrator", "camera",
// "materials" (name -> material), "geometry" (list), "lights" (list). See docs/scene-format.md.
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <set>
#include <string>

#include <glm/geometric.hpp>

#include "materials/material_parser.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/process/memory_limit.h"
#include "renderer/mesh/files/gltf_reader.h"
#include "renderer/scene/scene.h"
#include "renderer/scene/scene_transform.h"

namespace ofl {
namespace {

constexpr int kFormatVersion = 1;

IntegratorSpec parse_integrator(const JsonNode& n) {
  n.check_keys({"spp", "max_depth", "rr_start_depth", "seed", "wavelengths", "output_bands", "direct_excitation",
                "light_selection", "fluorescence", "noise_target", "regularize_glossy", "importance_camera"});
  IntegratorSpec s;
  s.spp = n.integer_or("spp", s.spp, 1, 1 << 24);
  s.max_depth = n.integer_or("max_depth", s.max_depth, 0, 100000);
  s.rr_start_depth = n.integer_or("rr_start_depth", s.rr_start_depth, 0, 100000);
  if (auto seed = n.find("seed")) s.seed = static_cast<uint64_t>(seed->integer(0));
  if (auto w = n.find("wavelengths")) {
    w->check_keys({"min_nm", "max_nm", "step_nm"});
    s.grid.min_nm = w->number_or("min_nm", s.grid.min_nm, 1.0, 1e5);
    s.grid.max_nm = w->number_or("max_nm", s.grid.max_nm, 1.0, 1e5);
    s.grid.step_nm = w->number_or("step_nm", s.grid.step_nm, 0.01, 1e4);
    if (auto p = s.grid.problem(); !p.empty()) w->fail(p);
  }
  // Without output_bands the image holds the whole wavelength grid: nothing the lights emit or the
  // surfaces re-emit is dropped before the camera (an excitation leak is the camera's question).
  s.bands = {s.grid.min_nm, s.grid.max_nm, s.grid.step_nm};
  if (auto b = n.find("output_bands")) {
    b->check_keys({"min_nm", "max_nm", "step_nm"});
    s.bands.min_nm = b->number_or("min_nm", s.bands.min_nm, 1.0);
    s.bands.max_nm = b->number_or("max_nm", s.bands.max_nm, 1.0);
    s.bands.step_nm = b->number_or("step_nm", s.bands.step_nm, 0.01);
    double nb = (s.bands.max_nm - s.bands.min_nm) / s.bands.step_nm;
    if (nb < 0 || std::fabs(nb - std::round(nb)) > 1e-6) b->fail("step_nm must divide max_nm - min_nm");
  }
  double lo = s.bands.min_nm - 0.5 * s.bands.step_nm, hi = s.bands.max_nm + 0.5 * s.bands.step_nm;
  if (lo < s.grid.bin_lo(0) - 1e-9 || hi > s.grid.bin_hi(s.grid.size() - 1) + 1e-9)
    n.fail("output bands " + std::to_string(lo) + "-" + std::to_string(hi) + " nm reach outside the wavelength grid");
  std::string de = n.choice_or("direct_excitation", "deterministic", {"deterministic", "sampled"});
  s.direct_excitation = de == "sampled" ? IntegratorSpec::DirectExcitation::kSampled : IntegratorSpec::DirectExcitation::kDeterministic;
  s.light_selection = n.choice_or("light_selection", "reach", {"reach", "power"}) == "power"
                          ? IntegratorSpec::LightSelection::kPower
                          : IntegratorSpec::LightSelection::kReach;
  s.fluorescence = n.boolean_or("fluorescence", true);
  s.noise_target = n.number_or("noise_target", 0.0, 0.0, 1.0);
  s.regularize_glossy = n.number_or("regularize_glossy", 0.0, 0.0, 1.0);
  if (auto c = n.find("importance_camera")) s.importance_camera = c->existing_file().string();
  return s;
}

int material_index(const Scene& sc, const std::string& name) {
  for (size_t i = 0; i < sc.materials.size(); ++i)
    if (sc.materials[i].name == name) return static_cast<int>(i);
  return -1;
}

int require_material(const Scene& sc, const JsonNode& n) {
  std::string name = n.string();
  int i = material_index(sc, name);
  if (i < 0) n.fail("no material named \"" + name + "\" in /materials");
  return i;
}

void parse_geometry(Scene& sc, const JsonNode& list) {
  for (size_t gi = 0; gi < list.size(); ++gi) {
    JsonNode g = list.at(gi);
    std::string type = g.at("type").string();
    if (type == "gltf") {
      g.check_keys({"type", "file", "transform", "materials", "default_material"});
      glm::dmat4 world = g.find("transform") ? parse_transform(g.at("transform")) : glm::dmat4(1.0);
      auto file = g.at("file").existing_file();
      auto meshes = g.at("file").read_file([&](const std::filesystem::path& p) { return read_gltf(p, world); }).meshes;
      if (meshes.empty()) g.at("file").fail("the glTF file has no triangle meshes");
      for (auto& m : meshes) {
        std::string scene_name = m.material;
        if (auto map = g.find("materials"); map && map->has(m.material)) scene_name = map->at(m.material).string();
        m.material_id = material_index(sc, scene_name);
        if (m.material_id < 0 && g.has("default_material")) m.material_id = require_material(sc, g.at("default_material"));
        if (m.material_id < 0)
          g.fail("glTF material \"" + m.material + "\" of " + file.string() +
                 " has no scene material of that name (add it to /materials, map it in \"materials\", or set \"default_material\")");
        sc.meshes.push_back(std::move(m));
      }
    } else if (type == "quad") {
      g.check_keys({"type", "center", "u", "v", "material"});
      glm::dvec3 c = g.at("center").vec3(), u = g.at("u").vec3(), v = g.at("v").vec3();
      if (glm::length(glm::cross(u, v)) < 1e-15) g.fail("u and v must span a plane");
      TriangleMesh m;
      m.name = "quad " + std::to_string(gi);
      m.material_id = require_material(sc, g.at("material"));
      m.material = g.at("material").string();
      glm::dvec3 p[4] = {c - 0.5 * u - 0.5 * v, c + 0.5 * u - 0.5 * v, c + 0.5 * u + 0.5 * v, c - 0.5 * u + 0.5 * v};
      glm::vec2 uv[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
      for (int k = 0; k < 4; ++k) { m.positions.push_back(glm::vec3(p[k])); m.uvs.push_back(uv[k]); }
      m.indices = {0, 1, 2, 0, 2, 3};
      sc.meshes.push_back(std::move(m));
    } else if (type == "sphere") {
      g.check_keys({"type", "center", "radius", "material"});
      sc.spheres.push_back({g.at("center").vec3(), g.at("radius").positive(), require_material(sc, g.at("material"))});
    } else if (type == "disk") {
      g.check_keys({"type", "center", "normal", "radius", "material"});
      sc.disks.push_back({g.at("center").vec3(), g.at("normal").unit_vec3(), g.at("radius").positive(), require_material(sc, g.at("material"))});
    } else {
      g.at("type").fail("unknown geometry type \"" + type + "\" (expected gltf, quad, sphere, disk)");
    }
  }
}

// How a material carries light sideways: 0 not at all (a surface, "table", "walk"), 1 by the
// spatial transport's profiles, 2 by the volume walk.
int lateral_transport(const Material& m) {
  if (!m.stack.enabled) return 0;
  if (m.stack.transport == StackTransport::kSpatial) return 1;
  return m.stack.transport == StackTransport::kVolume ? 2 : 0;
}

// The volume walk moves sideways from one material's column into another's at the same depth: the
// columns must end alike (both semi-infinite, or the same bottom at the same depth), or a walk could
// stand below one column's opaque base or open bottom inside another's tissue.
std::string column_end(const LayerStack& st) {
  double depth = 0;
  for (const auto& l : st.layers) depth += l.thickness_mm;
  if (st.bottom == StackBottom::kSemiInfinite) return "semi-infinite";
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s at %.6g mm", st.bottom == StackBottom::kBase ? "an opaque base" : "an open bottom", depth);
  return buf;
}

void check_volume_columns(const Scene& sc, const Material& m, const JsonNode& node) {
  const Material& base = sc.materials[m.regions_base];
  for (size_t k = 0; k < m.regions.size(); ++k) {
    const Material& r = sc.materials[m.regions[k].material];
    if (column_end(r.stack) == column_end(base.stack)) continue;
    node.at("regions").at(k).at("material").fail("\"" + r.name + "\" ends in " + column_end(r.stack) + " but \"" + base.name +
                                                 "\" in " + column_end(base.stack) +
                                                 ": the \"volume\" transport walks from one into the other at the same depth, "
                                                 "so their stacks must end alike");
  }
}

// Light that travels sideways crosses from one region into the next only between materials that
// carry it the same way: every material of a regions material uses the spatial transport, or every
// one the volume walk, or none of them carries light sideways.
void check_spatial_regions(const Scene& sc, const Material& m, const JsonNode& node) {
  const Material& base = sc.materials[m.regions_base];
  for (size_t k = 0; k < m.regions.size(); ++k) {
    const Material& r = sc.materials[m.regions[k].material];
    const int lr = lateral_transport(r), lb = lateral_transport(base);
    if (lr == lb) continue;
    const Material& sp = lr > lb ? r : base;
    const Material& other = lr > lb ? base : r;
    const std::string t = std::max(lr, lb) == 1 ? "spatial" : "volume";
    node.at("regions").at(k).at("material").fail(
        "\"" + sp.name + "\" uses the \"" + t + "\" transport but \"" + other.name +
        "\" does not: light travelling sideways between regions needs every material of \"" + m.name +
        "\" to be layered_tissue with \"transport\": \"" + t + "\"");
  }
  if (lateral_transport(base) == 2) check_volume_columns(sc, m, node);
}

// "regions" materials name other materials: resolve them now that all are read. A region may not
// itself be a regions material (no chains, no cycles).
void resolve_regions(Scene& sc, const JsonNode& mats) {
  for (auto& m : sc.materials) {
    if (!m.dispatches()) continue;
    JsonNode node = mats.at(m.name);
    auto resolve = [&](const std::string& name, const JsonNode& where) {
      int i = material_index(sc, name);
      if (i < 0) where.fail("no material named \"" + name + "\" in /materials");
      if (sc.materials[i].dispatches()) where.fail("\"" + name + "\" is itself a regions material; name a surface material");
      return i;
    };
    m.regions_base = resolve(m.regions_base_name, node.at("base"));
    for (size_t k = 0; k < m.regions.size(); ++k) m.regions[k].material = resolve(m.regions[k].material_name, node.at("regions").at(k).at("material"));
    check_spatial_regions(sc, m, node);
  }
}

}  // namespace

int resolve_material(const Scene& sc, int material, float u, float v, const glm::dvec3& p) {
  if (material < 0) return material;
  const Material& m = sc.materials[material];
  if (!m.dispatches()) return material;
  for (const auto& r : m.regions) {
    if (r.sphere) {
      const glm::dvec3 d = p - glm::dvec3(r.centre_m[0], r.centre_m[1], r.centre_m[2]);
      if (glm::dot(d, d) < r.radius_m * r.radius_m) return r.material;
    } else if (sc.textures[r.texture].lookup(u, v) > r.threshold) {
      return r.material;
    }
  }
  return m.regions_base;
}

namespace {

// A texture mask's bound (region_clearance_m): the side distance at the texel nearest (u, v), less
// the 1.5 sqrt 2 texels within which bilinear interpolation from a texel of the other side reaches,
// converted to metres by the largest stretch of texels per metre along the plane (the square root
// of the largest eigenvalue of the texel-space Gram matrix).
double mask_clearance_m(const Texture& t, const MaterialRegion& r, float u, float v, const UvMetric& g) {
  const double a = g.uu * t.width * t.width, b = g.uv * t.width * t.height, c = g.vv * t.height * t.height;
  const double stretch = std::sqrt(0.5 * (a + c) + std::sqrt(0.25 * (a - c) * (a - c) + b * b));
  if (!(stretch > 0)) return std::numeric_limits<double>::infinity();  // the mask reads one point
  if (r.side_distance.size() != t.texels.size()) return 0.0;
  const int x = std::clamp(int(std::floor((u - std::floor(u)) * t.width)), 0, t.width - 1);
  const int y = std::clamp(int(std::floor((v - std::floor(v)) * t.height)), 0, t.height - 1);
  const double texels = double(r.side_distance[size_t(y) * t.width + x]) - 1.5 * std::sqrt(2.0);
  return texels > 0 ? texels / stretch : 0.0;
}

double clearance_m(const Scene& sc, int material, const glm::dvec3& p, const float* uv, const UvMetric& g) {
  if (material < 0) return std::numeric_limits<double>::infinity();
  const Material& m = sc.materials[material];
  if (!m.dispatches()) return std::numeric_limits<double>::infinity();
  double clear = std::numeric_limits<double>::infinity();
  for (const auto& r : m.regions) {
    if (!r.sphere) {
      if (!uv) return 0.0;
      clear = std::min(clear, mask_clearance_m(sc.textures[size_t(r.texture)], r, uv[0], uv[1], g));
      continue;
    }
    const glm::dvec3 d = p - glm::dvec3(r.centre_m[0], r.centre_m[1], r.centre_m[2]);
    clear = std::min(clear, std::abs(glm::length(d) - r.radius_m));
  }
  return clear;
}

}  // namespace

double region_clearance_m(const Scene& sc, int material, const glm::dvec3& p, float u, float v, const UvMetric& metric) {
  const float uv[2] = {u, v};
  return clearance_m(sc, material, p, uv, metric);
}

double region_clearance_m(const Scene& sc, int material, const glm::dvec3& p) { return clearance_m(sc, material, p, nullptr, {}); }

Scene load_scene(const std::filesystem::path& file, const SceneOverrides& ov) { return load_scene(JsonFile::load(file), ov); }

Scene load_scene(const JsonFile& doc, const SceneOverrides& ov) {
  JsonNode r = doc.root();
  r.check_keys({"format", "version", "description", "integrator", "camera", "materials", "geometry", "lights"});
  if (auto f = r.find("format"); f && f->string() != "oralfluor-scene") f->fail("expected \"oralfluor-scene\"");
  int version = r.at("version").integer();
  if (version != kFormatVersion)
    r.at("version").fail("unsupported scene format version " + std::to_string(version) + " (this build reads " +
                         std::to_string(kFormatVersion) + ")");
  Scene sc;
  sc.file = doc.name();
  sc.integrator = r.find("integrator") ? parse_integrator(r.at("integrator")) : IntegratorSpec{};
  if (ov.spp) sc.integrator.spp = *ov.spp;
  if (ov.seed) sc.integrator.seed = *ov.seed;
  sc.camera = parse_camera_spec(r.at("camera"));
  // One side alone keeps the scene's aspect ratio; both set the image size exactly.
  double aspect = double(sc.camera.height) / sc.camera.width;
  if (ov.width) sc.camera.width = *ov.width;
  if (ov.height) sc.camera.height = *ov.height;
  if (ov.width && !ov.height) sc.camera.height = std::max(1, int(std::lround(*ov.width * aspect)));
  if (ov.height && !ov.width) sc.camera.width = std::max(1, int(std::lround(*ov.height / aspect)));
  {
    // The film: per pixel and output band two double sums (radiance, fluorescence) and two float
    // planes of the image, plus noise halves and AOVs per pixel. Checked before the scene is built.
    const double px = double(sc.camera.width) * sc.camera.height, bands = sc.integrator.bands.size();
    check_memory(doc.name(), ov.width || ov.height ? "--width/--height" : "/camera/resolution",
                 px * (bands * 24.0 + 64.0),
                 "a " + std::to_string(sc.camera.width) + "x" + std::to_string(sc.camera.height) + " render with " +
                     std::to_string(int(bands)) + " output bands");
  }

  MaterialContext ctx{sc.grid(), &sc.eems, &sc.textures, {}, {}};
  JsonNode mats = r.at("materials");
  for (const auto& name : mats.keys()) sc.materials.push_back(parse_material(name, mats.at(name), ctx));
  resolve_regions(sc, mats);
  parse_geometry(sc, r.at("geometry"));
  if (sc.meshes.empty() && sc.spheres.empty() && sc.disks.empty()) r.at("geometry").fail("the scene has no geometry");

  if (auto lights = r.find("lights")) {
    for (size_t i = 0; i < lights->size(); ++i)
      for (auto& l : parse_lights(lights->at(i), sc.grid())) sc.lights.push_back(std::move(l));
    // Lights with identical spectra share precomputed direct-excitation tables.
    for (size_t i = 0; i < sc.lights.size(); ++i) {
      sc.lights[i].spd_group = static_cast<int>(i);
      for (size_t j = 0; j < i; ++j) {
        double a = sc.lights[i].intensity_W_sr, b = sc.lights[j].intensity_W_sr;
        bool same = a > 0 && b > 0;
        for (size_t k = 0; same && k < sc.lights[i].spectral_intensity.size(); ++k)
          same = std::fabs(sc.lights[i].spectral_intensity[k] / a - sc.lights[j].spectral_intensity[k] / b) <= 1e-12 * (1.0 / a);
        if (same) { sc.lights[i].spd_group = sc.lights[j].spd_group; break; }
      }
    }
  }
  return sc;
}

}  // namespace ofl
