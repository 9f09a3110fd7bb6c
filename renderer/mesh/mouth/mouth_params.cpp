#include "renderer/mesh/mouth/mouth_params.h"

#include <algorithm>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"

namespace ofl {

const std::vector<MouthParamInfo>& mouth_param_table() {
  using P = MouthParams;
  static const std::vector<MouthParamInfo> t = {
      {"opening_m", &P::opening_m, 0.002, 0.08, "vertical gap between the inner lip edges at the midline (m)"},
      {"opening_width_m", &P::opening_width_m, 0.01, 0.09, "commissure to commissure, inner lip edges (m)"},
      {"opening_exponent", &P::opening_exponent, 1.5, 8, "superellipse exponent of the opening (2 = ellipse)"},
      {"lip_thickness_m", &P::lip_thickness_m, 0.002, 0.03, "diameter of the lip tube (m)"},
      {"lip_commissure_ratio", &P::lip_commissure_ratio, 0.1, 1, "lip diameter at the corners / at the midline"},
      {"lower_lip_setback_m", &P::lower_lip_setback_m, 0, 0.05, "lower lip behind the upper lip (m)"},
      {"face_width_m", &P::face_width_m, 0.05, 0.4, "outer width of the face plate (m)"},
      {"face_height_m", &P::face_height_m, 0.05, 0.4, "outer height of the face plate (m)"},
      {"face_recess_m", &P::face_recess_m, 0, 0.1, "face plate edge behind the lip plane (m)"},
      {"head_depth_m", &P::head_depth_m, 0.03, 0.5, "lip plane to the back of the head block (m)"},
      {"vestibule_depth_m", &P::vestibule_depth_m, 0.002, 0.1, "back of the lips to the full-size cavity (m)"},
      {"cavity_depth_m", &P::cavity_depth_m, 0.02, 0.4, "lip plane to the pharynx wall (m)"},
      {"cavity_width_m", &P::cavity_width_m, 0.02, 0.3, "cheek to cheek (m)"},
      {"cavity_exponent", &P::cavity_exponent, 1.5, 8, "superellipse exponent of the cavity cross-sections"},
      {"palate_height_m", &P::palate_height_m, 0.002, 0.15, "roof above z = 0 at the upper gum line (m)"},
      {"palate_vault_m", &P::palate_vault_m, 0, 0.05, "extra vault height at the midline (m)"},
      {"floor_depth_m", &P::floor_depth_m, -0.05, 0.15, "floor below z = 0 at the front of the cavity (m)"},
      {"floor_rise_m", &P::floor_rise_m, -0.1, 0.1, "floor rise from the front to the back of the cavity (m)"},
      {"tongue_protrusion_m", &P::tongue_protrusion_m, -0.2, 0.08, "x of the tongue tip; > 0 is outside the lip plane (m)"},
      {"tongue_length_m", &P::tongue_length_m, 0.01, 0.2, "tongue length, tip to back (m)"},
      {"tongue_width_m", &P::tongue_width_m, 0.005, 0.1, "tongue width at mid-length (m)"},
      {"tongue_thickness_m", &P::tongue_thickness_m, 0.002, 0.08, "tongue thickness at mid-length (m)"},
      {"tongue_dorsum_fraction", &P::tongue_dorsum_fraction, 0.1, 0.9, "share of the thickness above the mid-plane"},
      {"tongue_taper", &P::tongue_taper, -0.9, 0.9, "width change from mid-length to back (+) and tip (-), fraction"},
      {"tongue_tip_droop_m", &P::tongue_tip_droop_m, -0.05, 0.05, "sag of the tip below the mid-plane (m)"},
      {"tongue_back_droop_m", &P::tongue_back_droop_m, -0.05, 0.05, "sag of the back end below the mid-plane (m)"},
      {"tongue_pitch_deg", &P::tongue_pitch_deg, -60, 60, "rotation about y, positive tips the tip down (deg)"},
      {"tongue_center_z_m", &P::tongue_center_z_m, -0.1, 0.1, "height of the tongue mid-plane at mid-length (m)"},
  };
  return t;
}

void validate_mouth_params(const MouthParams& p, const std::string& name) {
  // Name the offending key as a JSON pointer in a file, or as its flag on the command line.
  auto fail = [&](const char* key, const std::string& what) {
    std::string field = std::string("/") + key;
    if (name == "command line") {
      field = std::string("--") + key;
      for (auto& c : field) if (c == '_') c = '-';
    }
    throw InputError(name, field, what);
  };
  const double r = p.lip_thickness_m / 2;
  const double x_cavity = r + p.vestibule_depth_m;  // depth where the full cavity starts
  if (p.segments < 16 || p.segments % 8 != 0 || p.segments > 4096) fail("segments", "must be a multiple of 8 in [16, 4096]");
  if (p.cavity_depth_m <= x_cavity + 0.005)
    fail("cavity_depth_m", "must exceed lip_thickness_m/2 + vestibule_depth_m by at least 5 mm");
  if (p.lower_lip_setback_m + r >= x_cavity)
    fail("lower_lip_setback_m", "the lower lip would reach into the cavity; increase vestibule_depth_m");
  if (p.head_depth_m <= p.cavity_depth_m + 0.005) fail("head_depth_m", "must exceed cavity_depth_m by at least 5 mm");
  if (p.face_recess_m + 0.005 >= p.head_depth_m) fail("face_recess_m", "must be smaller than head_depth_m");
  double roof = p.palate_height_m + p.palate_vault_m;
  double floor_front = -p.floor_depth_m, floor_back = -p.floor_depth_m + p.floor_rise_m;
  if (p.palate_height_m - std::max(floor_front, floor_back) < 0.004)
    fail("floor_rise_m", "the floor must stay at least 4 mm below the palate");
  if (p.cavity_width_m / 2 + 0.005 > p.face_width_m / 2) fail("cavity_width_m", "the cavity must fit inside face_width_m");
  if (p.opening_width_m / 2 + p.lip_thickness_m + 0.005 > p.face_width_m / 2)
    fail("opening_width_m", "the lips must fit inside face_width_m");
  double top = std::max(roof, p.opening_m / 2 + p.lip_thickness_m);
  double bottom = std::min(std::min(floor_front, floor_back), -p.opening_m / 2 - p.lip_thickness_m);
  if (top + 0.005 > p.face_height_m / 2 || -bottom + 0.005 > p.face_height_m / 2)
    fail("face_height_m", "the cavity and lips must fit inside face_height_m (the block is centred on z = 0)");
  if (p.opening_width_m / 2 + r > p.cavity_width_m / 2)
    fail("cavity_width_m", "must be at least as wide as the lips (opening_width_m + lip_thickness_m)");
}

MouthParams mouth_params_from_json(const nlohmann::json& doc, const std::string& name) {
  JsonFile file = JsonFile::from(doc, name);
  JsonNode root = file.root();
  if (!root.is_object()) root.fail("expected an object of mouth parameters");
  MouthParams p;
  for (const auto& key : root.keys()) {
    if (key == "tongue" || key == "segments" || key == "$comment") continue;
    bool known = false;
    for (const auto& info : mouth_param_table()) known |= key == info.key;
    if (!known) root.at(key).fail("unknown mouth parameter");
  }
  for (const auto& info : mouth_param_table())
    p.*info.member = root.number_or(info.key, p.*info.member, info.lo, info.hi);
  p.tongue = root.boolean_or("tongue", p.tongue);
  p.segments = root.integer_or("segments", p.segments, 16, 4096);
  validate_mouth_params(p, name);
  return p;
}

MouthParams read_mouth_params(const std::filesystem::path& file) {
  JsonFile f = JsonFile::load(file);
  return mouth_params_from_json(f.doc(), file.string());
}

nlohmann::json to_json(const MouthParams& p) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& info : mouth_param_table()) j[info.key] = p.*info.member;
  j["tongue"] = p.tongue;
  j["segments"] = p.segments;
  return j;
}

}  // namespace ofl
