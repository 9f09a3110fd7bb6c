#include "renderer/mesh/files/mesh_convert.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/errors/error.h"
#include "renderer/mesh/geometry/mesh_measure.h"
#include "renderer/mesh/files/obj_reader.h"

namespace ofl {

glm::dmat3 parse_axes(const std::string& spec) {
  glm::dmat3 m(0.0);  // column-major: m[col][row]
  int row = 0;
  bool used[3] = {false, false, false};
  size_t i = 0;
  auto bad = [&](const std::string& why) -> glm::dmat3 { throw InputError("command line", "--axes", why + " in '" + spec + "' (expected e.g. \"-z,x,-y\")"); };
  while (i <= spec.size() && row < 3) {
    size_t j = spec.find(',', i);
    if (j == std::string::npos) j = spec.size();
    std::string tok = spec.substr(i, j - i);
    double sign = 1;
    if (!tok.empty() && (tok[0] == '-' || tok[0] == '+')) {
      sign = tok[0] == '-' ? -1 : 1;
      tok = tok.substr(1);
    }
    if (tok.size() != 1 || tok[0] < 'x' || tok[0] > 'z') return bad("each axis must be x, y or z with an optional sign");
    int col = tok[0] - 'x';
    if (used[col]) return bad("axis " + tok + " used twice");
    used[col] = true;
    m[col][row] = sign;
    ++row;
    i = j + 1;
    if (j == spec.size()) break;
  }
  if (row != 3 || i < spec.size()) return bad("need exactly three axes");
  return m;
}

glm::dmat3 parse_rotation(const std::string& spec) {
  if (spec.empty()) return glm::dmat3(1.0);
  if (spec.size() < 3 || spec[0] < 'x' || spec[0] > 'z' || spec[1] != ':')
    throw InputError("command line", "--rotate", "expected AXIS:DEGREES such as y:19.6, found '" + spec + "'");
  double deg = 0;
  try {
    size_t used = 0;
    deg = std::stod(spec.substr(2), &used);
    if (used != spec.size() - 2) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    throw InputError("command line", "--rotate", "not a number of degrees in '" + spec + "'");
  }
  const double a = deg * 3.14159265358979323846 / 180.0, c = std::cos(a), s = std::sin(a);
  int k = spec[0] - 'x', i = (k + 1) % 3, j = (k + 2) % 3;
  glm::dmat3 m(1.0);  // rotates axis i towards axis j
  m[i][i] = c;
  m[j][j] = c;
  m[i][j] = s;
  m[j][i] = -s;
  return m;
}

GlbDocument convert_obj(const std::filesystem::path& obj, const ConvertOptions& opt, ConvertReport* report) {
  ObjContents in = read_obj(obj);
  GlbDocument doc;
  for (auto& m : in.meshes) {
    if (!opt.groups.empty() && std::find(opt.groups.begin(), opt.groups.end(), m.name) == opt.groups.end()) continue;
    doc.meshes.push_back(std::move(m));
  }
  if (doc.meshes.empty())
    throw InputError(obj.string(), opt.groups.empty() ? "" : "--group", "no faces to convert");

  glm::dmat3 axes = parse_rotation(opt.rotate) * parse_axes(opt.axes);
  for (auto& m : doc.meshes) transform_mesh(m, axes, glm::dvec3(0.0));
  double scale = opt.scale;
  if (opt.target_width_m) {
    double w = mesh_bounds(doc.meshes).size()[opt.width_axis];
    if (!(w > 0)) throw InputError(obj.string(), "--target-width-m", "the mesh has no extent along that axis");
    scale = *opt.target_width_m / w;
  }
  if (!(scale > 0) || !std::isfinite(scale)) throw InputError("command line", "--scale", "must be positive");
  for (auto& m : doc.meshes) transform_mesh(m, glm::dmat3(scale), glm::dvec3(0.0));
  glm::dvec3 shift = opt.translate;
  if (opt.center) shift -= mesh_bounds(doc.meshes).center();
  for (auto& m : doc.meshes) translate_mesh(m, shift);
  for (auto& m : doc.meshes) {
    if (!opt.material_name.empty()) m.material = opt.material_name;
    if (m.material.empty()) m.material = "default";
  }
  if (opt.merge && doc.meshes.size() > 1) {
    // One mesh per material, named after the output's first material.
    std::vector<TriangleMesh> merged;
    for (auto& m : doc.meshes) {
      auto it = std::find_if(merged.begin(), merged.end(), [&](const TriangleMesh& x) { return x.material == m.material; });
      if (it == merged.end()) {
        merged.push_back(std::move(m));
        merged.back().name = merged.back().material;
      } else {
        append_mesh(*it, m);
      }
    }
    doc.meshes = std::move(merged);
  } else if (opt.merge) {
    doc.meshes[0].name = doc.meshes[0].material;
  }

  doc.generator = "oralfluor mesh convert";
  doc.extras = {{"source", obj.filename().string()},
                {"metres_per_source_unit", scale},
                {"axes", opt.axes},
                {"rotate", opt.rotate},
                {"translate_m", {shift.x, shift.y, shift.z}}};
  if (report) {
    *report = ConvertReport{};
    report->scale = scale;
    report->meshes = doc.meshes.size();
    report->polygons_triangulated = in.polygons_triangulated;
    for (auto& m : doc.meshes) {
      report->vertices += m.vertex_count();
      report->triangles += m.triangle_count();
      report->area_m2 += surface_area(m);
    }
    Bounds b = mesh_bounds(doc.meshes);
    report->bounds_min = b.min;
    report->bounds_max = b.max;
  }
  return doc;
}

}  // namespace ofl
