#include "renderer/sweep/design/rig_generators.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <glm/vec3.hpp>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"

namespace ofl {
namespace {

nlohmann::json read_json(const std::filesystem::path& p, const std::string& file, const std::string& field) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw InputError(file, field, "cannot open " + p.string());
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_json_text(ss.str(), p.string());
}

std::filesystem::path relative_to(const std::string& sweep_file, const std::string& path) {
  std::filesystem::path p = path;
  return p.is_relative() ? std::filesystem::path(sweep_file).parent_path() / p : p;
}

// The light a generator edits; `ring` requires an "led_ring".
nlohmann::json& light_at(nlohmann::json& scene, const SweepParameter& p, bool ring, const std::string& file) {
  if (!scene.contains("lights") || !scene["lights"].is_array() || p.light >= int(scene["lights"].size()))
    throw InputError(file, p.where + "/light", "the scene has no light " + std::to_string(p.light));
  nlohmann::json& l = scene["lights"][p.light];
  if (ring && l.value("type", std::string("led")) != "led_ring")
    throw InputError(file, p.where + "/generator", "generator " + p.generator + " needs an \"led_ring\" light at /lights/" +
                                                       std::to_string(p.light));
  return l;
}

glm::dvec3 vec3_of(const nlohmann::json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
    throw InputError("", what, "expected [x, y, z]");
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}
nlohmann::json json_of(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

}  // namespace

void set_at_pointer(nlohmann::json& doc, const std::string& pointer, const nlohmann::json& value, const std::string& file,
                    const std::string& field) {
  nlohmann::json::json_pointer ptr(pointer);
  nlohmann::json::json_pointer parent = ptr.parent_pointer();
  if (!doc.contains(parent))
    throw InputError(file, field, "the document has nothing at " + (parent.to_string().empty() ? "/" : parent.to_string()) +
                                      " (the parent of " + pointer + ")");
  nlohmann::json& par = doc.at(parent);
  const std::string key = ptr.back();
  if (par.is_object()) {
    if (value.is_null()) par.erase(key);
    else par[key] = value;
  } else if (par.is_array()) {
    char* end = nullptr;
    long idx = std::strtol(key.c_str(), &end, 10);
    if (key.empty() || *end != '\0' || idx < 0 || idx >= long(par.size()))
      throw InputError(file, field, pointer + ": array index \"" + key + "\" out of range (size " +
                                        std::to_string(par.size()) + ")");
    if (value.is_null()) par.erase(size_t(idx));
    else par[size_t(idx)] = value;
  } else {
    throw InputError(file, field, pointer + ": the parent is a " + std::string(par.type_name()) + ", not an object or array");
  }
}

void move_rig_to_distance(nlohmann::json& scene, double d) {
  if (!scene.contains("camera")) throw InputError("", "/camera", "missing");
  nlohmann::json& cam = scene["camera"];
  glm::dvec3 p = vec3_of(cam.value("position", nlohmann::json()), "/camera/position");
  glm::dvec3 t = vec3_of(cam.value("look_at", nlohmann::json()), "/camera/look_at");
  glm::dvec3 dir = t - p;
  double d0 = std::sqrt(dir.x * dir.x + dir.y * dir.y + dir.z * dir.z);
  if (!(d0 > 0)) throw InputError("", "/camera/look_at", "equals position");
  dir /= d0;
  glm::dvec3 delta = (t - d * dir) - p;  // look_at stays: it is the tissue point the camera aims at
  cam["position"] = json_of(p + delta);
  if (!scene.contains("lights")) return;
  for (auto& l : scene["lights"]) {
    // A rigid move: positions and aim points shift together, so every LED axis keeps its direction.
    for (const char* k : {"position", "center", "target"})
      if (l.contains(k)) l[k] = json_of(vec3_of(l[k], std::string("/lights/") + k) + delta);
  }
}

void apply_parameter(const SweepParameter& p, const nlohmann::json& v, PointDocuments& docs, const std::string& sweep_file) {
  const std::string field = p.where;
  try {
    switch (p.kind) {
      case ParamKind::kScenePath: set_at_pointer(docs.scene, p.pointer, v, sweep_file, field + "/scene"); return;
      case ParamKind::kCameraPath: set_at_pointer(docs.camera, p.pointer, v, sweep_file, field + "/camera"); return;
      case ParamKind::kVariants: {
        for (size_t i = 0; i < p.variants.size(); ++i) {
          const Variant& var = p.variants[i];
          if (var.label != v) continue;
          for (auto& [ptr, x] : var.scene_edits)
            set_at_pointer(docs.scene, ptr, x, sweep_file, field + "/variants/" + std::to_string(i) + "/scene");
          for (auto& [ptr, x] : var.camera_edits)
            set_at_pointer(docs.camera, ptr, x, sweep_file, field + "/variants/" + std::to_string(i) + "/camera");
          return;
        }
        throw InputError(sweep_file, field, "no variant labelled " + v.dump());
      }
      case ParamKind::kGenerator: break;
    }
    const std::string& g = p.generator;
    if (g == "scene_file") {
      docs.scene_file = relative_to(sweep_file, v.get<std::string>());
      docs.scene = read_json(docs.scene_file, sweep_file, field);
    } else if (g == "camera_file") {
      docs.camera_file = relative_to(sweep_file, v.get<std::string>());
      docs.camera = read_json(docs.camera_file, sweep_file, field);
    } else if (g == "led_count") {
      light_at(docs.scene, p, true, sweep_file)["count"] = v;
    } else if (g == "ring_radius") {
      light_at(docs.scene, p, true, sweep_file)["ring_radius_m"] = v;
    } else if (g == "led_tilt") {
      nlohmann::json& l = light_at(docs.scene, p, true, sweep_file);
      l.erase("aim_distance_m");
      l["tilt_deg"] = v;
    } else if (g == "rig_distance") {
      move_rig_to_distance(docs.scene, v.get<double>());
    } else if (g == "led_half_angle") {
      light_at(docs.scene, p, false, sweep_file)["profile"] = {{"half_angle_deg", v}};
    } else if (g == "led_filter_edge") {
      nlohmann::json& l = light_at(docs.scene, p, false, sweep_file);
      nlohmann::json* f = nullptr;
      if (l.contains("filter") && l["filter"].is_object() && l["filter"].contains("edge_nm")) f = &l["filter"];
      else if (l.contains("filters") && l["filters"].is_array())
        for (auto& x : l["filters"])
          if (!f && x.is_object() && x.contains("edge_nm")) f = &x;
      if (!f) throw InputError(sweep_file, field, "light " + std::to_string(p.light) + " has no parametric filter with edge_nm");
      (*f)["edge_nm"] = v;
    } else if (g == "camera_filter_edge") {
      nlohmann::json& fs = docs.camera["filters"];
      if (!fs.is_array()) throw InputError(sweep_file, field, "the camera has no filters");
      int k = p.filter;
      if (k < 0)
        for (size_t i = 0; i < fs.size() && k < 0; ++i)
          if (fs[i].value("type", std::string()) == "longpass") k = int(i);
      if (k < 0 || k >= int(fs.size()) || !fs[k].contains("edge_nm"))
        throw InputError(sweep_file, field, p.filter < 0 ? "the camera has no longpass filter" :
                                                           "camera filter " + std::to_string(p.filter) + " has no edge_nm");
      fs[k]["edge_nm"] = v;
    } else if (g == "led_fwhm") {
      nlohmann::json& l = light_at(docs.scene, p, false, sweep_file);
      double peak = p.peak_nm;
      if (peak <= 0) {
        const nlohmann::json& s = l.value("spd", nlohmann::json());
        if (s.is_object() && s.value("type", std::string()) == "gaussian" && s.contains("peak_nm")) peak = s["peak_nm"].get<double>();
        else throw InputError(sweep_file, field + "/peak_nm", "the LED's spd is not a Gaussian: give peak_nm");
      }
      l["spd"] = {{"type", "gaussian"}, {"peak_nm", peak}, {"fwhm_nm", v}};
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(sweep_file, field, std::string("cannot apply value ") + v.dump() + ": " + e.what());
  } catch (const InputError& e) {
    if (e.file().empty()) throw InputError(sweep_file, field, e.field() + ": " + e.what());
    throw;
  }
}

PointDocuments point_documents(const SweepSpec& spec, const std::vector<nlohmann::json>& values) {
  PointDocuments d;
  d.scene_file = spec.scene;
  d.camera_file = spec.camera;
  d.scene = read_json(spec.scene, spec.file, "/scene");
  d.camera = read_json(spec.camera, spec.file, "/camera");
  // File choices first: the other edits apply to the chosen file.
  for (size_t i = 0; i < spec.parameters.size(); ++i) {
    const auto& p = spec.parameters[i];
    if (p.kind == ParamKind::kGenerator && (p.generator == "scene_file" || p.generator == "camera_file"))
      apply_parameter(p, values.at(i), d, spec.file);
  }
  for (size_t i = 0; i < spec.parameters.size(); ++i) {
    const auto& p = spec.parameters[i];
    if (p.kind == ParamKind::kGenerator && (p.generator == "scene_file" || p.generator == "camera_file")) continue;
    apply_parameter(p, values.at(i), d, spec.file);
  }
  return d;
}

}  // namespace ofl
