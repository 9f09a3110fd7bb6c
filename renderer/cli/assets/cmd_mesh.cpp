// `oralfluor mesh`: mesh tools. `convert` (OBJ -> glTF binary in metres, new axes, material
// name), `mouth` (the procedural mouth from a parameter file), `texture` (tongue maps in UV
// space), `info` (sizes, areas, watertightness) and `preview` (a rasterised picture, no renderer).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/cli/assets/cmd_mesh_parts.h"
#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/png_writer.h"
#include "renderer/mesh/files/gltf_reader.h"
#include "renderer/mesh/files/gltf_writer.h"
#include "renderer/mesh/files/mesh_convert.h"
#include "renderer/mesh/geometry/mesh_measure.h"
#include "renderer/mesh/mesh_preview.h"
#include "renderer/mesh/files/obj_reader.h"

namespace ofl {
namespace {

glm::dvec3 parse_vec3(const std::string& s, const std::string& option) {
  glm::dvec3 v(0.0);
  int n = 0;
  size_t i = 0;
  try {
    while (n < 3) {
      size_t j = s.find(',', i);
      std::string tok = s.substr(i, j == std::string::npos ? std::string::npos : j - i);
      size_t used = 0;
      v[n++] = std::stod(tok, &used);
      if (used != tok.size()) throw std::invalid_argument("trailing");
      if (j == std::string::npos) break;
      i = j + 1;
    }
  } catch (const std::exception&) {
    n = -1;
  }
  if (n != 3) throw InputError("command line", option, "expected X,Y,Z in metres, found '" + s + "'");
  return v;
}

std::vector<TriangleMesh> load_meshes(const std::string& file) {
  std::filesystem::path p(file);
  if (p.extension() == ".obj") return read_obj(p).meshes;
  return read_gltf(p).meshes;
}

nlohmann::json describe(const TriangleMesh& m) {
  Bounds b = mesh_bounds(m);
  EdgeStats e = edge_stats(m);
  nlohmann::json j = {{"name", m.name}, {"material", m.material}, {"vertices", m.vertex_count()},
                      {"triangles", m.triangle_count()},
                      {"bounds_min_m", {b.min.x, b.min.y, b.min.z}}, {"bounds_max_m", {b.max.x, b.max.y, b.max.z}},
                      {"size_m", {b.size().x, b.size().y, b.size().z}}, {"area_m2", surface_area(m)},
                      {"watertight", e.watertight()}, {"boundary_edges", e.boundary},
                      {"consistently_oriented", e.consistently_oriented()}};
  if (e.watertight()) j["volume_m3"] = enclosed_volume(m);
  if (!m.uvs.empty()) {
    UvRange r = uv_range(m);
    j["uv_min"] = {r.min.x, r.min.y};
    j["uv_max"] = {r.max.x, r.max.y};
  }
  return j;
}

void register_convert(CLI::App& mesh) {
  struct Opts {
    std::string in, out, axes = "x,y,z", rotate, translate, material;
    double scale = 1.0, target_width = 0;
    char width_axis = 'x';
    bool center = false, merge = false, json = false;
    std::vector<std::string> groups;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = mesh.add_subcommand("convert", "convert a Wavefront OBJ to glTF 2.0 binary (.glb)");
  cmd->add_option("input", o->in, "OBJ file")->required();
  cmd->add_option("-o,--output", o->out, "output .glb")->required();
  auto* sc = cmd->add_option("--scale", o->scale, "metres per OBJ unit");
  auto* tw = cmd->add_option("--target-width-m", o->target_width, "scale so the extent along --width-axis is this (m)");
  sc->excludes(tw);
  cmd->add_option("--width-axis", o->width_axis, "output axis the target width is measured along (x, y, z)")
      ->check(CLI::IsMember({'x', 'y', 'z'}));
  cmd->add_option("--axes", o->axes, "output x,y,z as signed input axes, e.g. -z,x,-y (applied before scaling)");
  cmd->add_option("--rotate", o->rotate, "AXIS:DEGREES, a right-handed rotation about an output axis after --axes");
  cmd->add_flag("--center", o->center, "centre the bounding box on the origin");
  cmd->add_option("--translate", o->translate, "X,Y,Z in metres, added after scaling and centring");
  cmd->add_option("--material-name", o->material, "glTF material name for every face");
  cmd->add_flag("--merge", o->merge, "one glTF mesh per material instead of one per OBJ group");
  cmd->add_option("--group", o->groups, "keep only this OBJ group/object (repeatable)");
  cmd->add_flag("--json", o->json, "print the report as JSON");
  cmd->callback([o] {
    ConvertOptions c;
    c.scale = o->scale;
    if (o->target_width > 0) c.target_width_m = o->target_width;
    c.width_axis = o->width_axis - 'x';
    c.axes = o->axes;
    c.rotate = o->rotate;
    c.center = o->center;
    if (!o->translate.empty()) c.translate = parse_vec3(o->translate, "--translate");
    c.material_name = o->material;
    c.merge = o->merge;
    c.groups = o->groups;
    ConvertReport rep;
    GlbDocument doc = convert_obj(o->in, c, &rep);
    write_glb(o->out, doc);
    glm::dvec3 size = rep.bounds_max - rep.bounds_min;
    if (o->json) {
      nlohmann::json j = {{"output", o->out}, {"scale_m_per_unit", rep.scale}, {"meshes", rep.meshes},
                          {"vertices", rep.vertices}, {"triangles", rep.triangles},
                          {"polygons_triangulated", rep.polygons_triangulated},
                          {"bounds_min_m", {rep.bounds_min.x, rep.bounds_min.y, rep.bounds_min.z}},
                          {"bounds_max_m", {rep.bounds_max.x, rep.bounds_max.y, rep.bounds_max.z}},
                          {"size_m", {size.x, size.y, size.z}}, {"area_m2", rep.area_m2}};
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      std::printf("wrote %s: %zu mesh(es), %zu vertices, %zu triangles (%zu polygons triangulated)\n", o->out.c_str(),
                  rep.meshes, rep.vertices, rep.triangles, rep.polygons_triangulated);
      std::printf("scale %.6g m/unit; size %.4f x %.4f x %.4f m; bounds [%.4f %.4f %.4f] .. [%.4f %.4f %.4f]; area %.6g m^2\n",
                  rep.scale, size.x, size.y, size.z, rep.bounds_min.x, rep.bounds_min.y, rep.bounds_min.z,
                  rep.bounds_max.x, rep.bounds_max.y, rep.bounds_max.z, rep.area_m2);
    }
  });
}

void register_info(CLI::App& mesh) {
  struct Opts {
    std::string in;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = mesh.add_subcommand("info", "sizes, areas, volumes and watertightness of an OBJ or glTF file");
  cmd->add_option("input", o->in, ".obj, .glb or .gltf")->required();
  cmd->add_flag("--json", o->json, "print JSON");
  cmd->callback([o] {
    std::vector<TriangleMesh> meshes = load_meshes(o->in);
    nlohmann::json j = {{"file", o->in}, {"meshes", nlohmann::json::array()}};
    for (auto& m : meshes) j["meshes"].push_back(describe(m));
    Bounds b = mesh_bounds(meshes);
    EdgeStats e = edge_stats(meshes);
    j["total"] = {{"bounds_min_m", {b.min.x, b.min.y, b.min.z}}, {"bounds_max_m", {b.max.x, b.max.y, b.max.z}},
                  {"size_m", {b.size().x, b.size().y, b.size().z}}, {"watertight", e.watertight()},
                  {"boundary_edges", e.boundary}, {"non_manifold_edges", e.non_manifold}};
    if (e.watertight()) j["total"]["volume_m3"] = enclosed_volume(meshes);
    if (std::filesystem::path(o->in).extension() != ".obj") {
      GltfContents g = read_gltf(o->in);
      j["anchors"] = nlohmann::json::object();
      for (auto& a : g.anchors) j["anchors"][a.name] = {a.position.x, a.position.y, a.position.z};
    }
    if (o->json) {
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    std::printf("%-18s %-10s %8s %8s  %-26s %-26s %10s %s\n", "mesh", "material", "verts", "tris", "min (m)", "max (m)",
                "area cm^2", "watertight");
    for (auto& m : j["meshes"]) {
      auto v3 = [](const nlohmann::json& a) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.4f %.4f %.4f", a[0].get<double>(), a[1].get<double>(), a[2].get<double>());
        return std::string(buf);
      };
      std::printf("%-18s %-10s %8zu %8zu  %-26s %-26s %10.2f %s\n", m["name"].get<std::string>().c_str(),
                  m["material"].get<std::string>().c_str(), m["vertices"].get<size_t>(), m["triangles"].get<size_t>(),
                  v3(m["bounds_min_m"]).c_str(), v3(m["bounds_max_m"]).c_str(), m["area_m2"].get<double>() * 1e4,
                  m["watertight"].get<bool>() ? "yes" : "no");
    }
    std::printf("total size %.4f x %.4f x %.4f m, watertight %s\n", b.size().x, b.size().y, b.size().z,
                e.watertight() ? "yes" : "no");
    if (j.contains("anchors"))
      for (auto& [name, p] : j["anchors"].items())
        std::printf("anchor %-22s %.4f %.4f %.4f\n", name.c_str(), p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
  });
}

void register_preview(CLI::App& mesh) {
  struct Opts {
    std::vector<std::string> inputs, overlays;
    std::string out, view = "front", clip, eye, target;
    int size = 512;
    double fov = 0;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = mesh.add_subcommand("preview", "rasterise meshes to a PNG (no path tracing) to check placement");
  cmd->add_option("inputs", o->inputs, ".glb/.gltf/.obj files, drawn together")->required();
  cmd->add_option("-o,--output", o->out, "output PNG")->required();
  cmd->add_option("--view", o->view, "front, side, top, iso or camera; several comma-separated are tiled side by side");
  cmd->add_option("--size", o->size, "pixels per view (square)")->check(CLI::Range(16, 4096));
  cmd->add_option("--clip", o->clip, "keep only one side of a plane, e.g. y<0 for a sagittal cut-away");
  cmd->add_option("--eye", o->eye, "perspective camera position X,Y,Z (m), with --look-at");
  cmd->add_option("--look-at", o->target, "perspective camera target X,Y,Z (m)");
  cmd->add_option("--fov", o->fov, "perspective vertical field of view (degrees)");
  cmd->add_option("--overlay", o->overlays, "MATERIAL=map.png[@R,G,B]: paint a grayscale UV map over a material (repeatable)");
  cmd->callback([o] {
    std::vector<TriangleMesh> meshes;
    for (auto& f : o->inputs) {
      auto m = load_meshes(f);
      meshes.insert(meshes.end(), m.begin(), m.end());
    }
    PreviewOptions opt;
    opt.width = opt.height = o->size;
    opt.clip = parse_clip(o->clip);
    for (auto& spec : o->overlays) opt.overlays.push_back(parse_overlay(spec));
    std::vector<PreviewCamera> cams;
    if (!o->eye.empty()) {
      PreviewCamera c;
      c.perspective = true;
      c.eye = parse_vec3(o->eye, "--eye");
      c.target = o->target.empty() ? glm::dvec3(0.0) : parse_vec3(o->target, "--look-at");
      c.fov_deg = o->fov > 0 ? o->fov : 60;
      cams.push_back(c);
    } else {
      size_t i = 0;
      while (i <= o->view.size()) {
        size_t j = o->view.find(',', i);
        if (j == std::string::npos) j = o->view.size();
        cams.push_back(named_view(o->view.substr(i, j - i)));
        if (o->fov > 0) cams.back().fov_deg = o->fov;
        i = j + 1;
      }
    }
    const int n = static_cast<int>(cams.size()), s = o->size;
    std::vector<float> sheet(static_cast<size_t>(n) * s * s * 3);
    for (int k = 0; k < n; ++k) {
      std::vector<float> img = render_preview(meshes, cams[k], opt);
      for (int y = 0; y < s; ++y)
        for (int x = 0; x < s; ++x)
          for (int c = 0; c < 3; ++c)
            sheet[(static_cast<size_t>(y) * n * s + k * s + x) * 3 + c] = img[(static_cast<size_t>(y) * s + x) * 3 + c];
    }
    write_srgb_png(o->out, n * s, s, sheet, 1.0);
    std::printf("wrote %s (%d view(s), %zu meshes)\n", o->out.c_str(), n, meshes.size());
  });
}

}  // namespace

void register_mesh_command(CLI::App& app) {
  auto* mesh = app.add_subcommand("mesh", "mesh tools: convert OBJ to glTF, procedural mouth, tongue texture maps, info, preview");
  mesh->require_subcommand(1);
  register_convert(*mesh);
  register_mouth_command(*mesh);
  register_texture_command(*mesh);
  register_info(*mesh);
  register_preview(*mesh);
}

}  // namespace ofl
