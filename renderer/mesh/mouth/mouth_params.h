// The parameters of the procedural mouth (`oralfluor mesh mouth`), one plain struct with
// defaults. Its JSON form (keys = member names) is what sweeps vary; every key is optional and
// unknown keys are errors. Lengths in metres, angles in degrees.
//
// The mouth frame (shared with assets/meshes/tongue.glb and teeth.glb): origin at the centre
// of the lip opening, +x out of the mouth (towards a camera in front of it), +z up (the upper
// occlusal plane is horizontal), +y the patient's left. The defaults are measured so that the
// SOFA teeth and tongue, converted as assets/meshes/README.md says, sit inside this mouth with
// no transform; see `mouth_anchors` for the named points.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ofl {

struct MouthParams {
  // Lips and opening. The lips are one swept tube around a superellipse opening.
  double opening_m = 0.050;            // vertical gap between the inner lip edges at the midline
  double opening_width_m = 0.050;      // commissure to commissure, between the inner lip edges
  double opening_exponent = 2.5;       // superellipse exponent of the opening (2 = ellipse, larger = squarer)
  double lip_thickness_m = 0.012;      // diameter of the lip tube at the midline
  double lip_commissure_ratio = 0.6;   // lip tube diameter at the corners / at the midline
  double lower_lip_setback_m = 0.020;  // the lower lip sits this far behind the upper (the jaw is open)

  // Face and head block: a closed box-like body the cavity is cut into (never seen from a
  // camera in front of the mouth, but it makes the solid watertight).
  double face_width_m = 0.140;         // outer width of the face plate
  double face_height_m = 0.140;        // outer height of the face plate
  double face_recess_m = 0.015;        // how far behind the lip plane the face plate's edge lies
  double head_depth_m = 0.170;         // from the lip plane to the back of the head block

  // Oral cavity behind the lips: superellipse cross-sections with a palatal vault on top.
  double vestibule_depth_m = 0.030;    // from the back of the lips to where the cavity reaches full size
  double cavity_depth_m = 0.120;       // from the lip plane to the (flat) pharynx wall
  double cavity_width_m = 0.088;       // cheek to cheek
  double cavity_exponent = 4.0;        // superellipse exponent of the cross-sections
  double palate_height_m = 0.029;      // roof (at the gum line of the upper teeth) above z = 0
  double palate_vault_m = 0.012;       // extra height of the palatal vault at the midline
  double floor_depth_m = 0.033;        // floor below z = 0 at the front of the cavity
  double floor_rise_m = 0.037;         // the floor rises by this much from front to back (open jaw)

  // Procedural tongue: a superellipsoid with a taper and droops (all volume-preserving), so
  // sweeps can vary the anatomy without the SOFA tongue.
  bool tongue = true;                  // include the procedural tongue (material "tongue")
  double tongue_protrusion_m = 0.010;  // x of the tongue tip: > 0 sticks out past the lip plane
  double tongue_length_m = 0.080;      // tip to back before droop
  double tongue_width_m = 0.050;       // width at mid-length (tip and back follow the taper)
  double tongue_thickness_m = 0.022;   // total thickness at mid-length
  double tongue_dorsum_fraction = 0.6; // share of the thickness above the mid-plane (domed dorsum)
  double tongue_taper = 0.15;          // width changes by +-this fraction from mid-length to back/tip
  double tongue_tip_droop_m = 0.020;   // the tip sags this far below the mid-plane (parabolic)
  double tongue_back_droop_m = 0.0;    // the back end sags this far (negative: rises)
  double tongue_pitch_deg = 0.0;       // rotation about y; positive tips the tip down
  double tongue_center_z_m = -0.003;   // height of the tongue's mid-plane at mid-length

  // Tessellation.
  int segments = 160;                  // vertices around each ring (multiple of 8)
};

// One row of the parameter table: JSON key, CLI flag, range, documentation.
struct MouthParamInfo {
  const char* key;
  double MouthParams::*member;
  double lo, hi;
  const char* doc;
};
const std::vector<MouthParamInfo>& mouth_param_table();

// Reads a JSON object (keys as in the struct, all optional) over the defaults; errors name the
// file and JSON path. Also checks relations between parameters (e.g. the cavity must fit in
// the head block), reporting the offending key.
MouthParams read_mouth_params(const std::filesystem::path& file);
MouthParams mouth_params_from_json(const nlohmann::json& j, const std::string& name);
// Throws InputError(name, "/key", ...) when parameters contradict each other.
void validate_mouth_params(const MouthParams& p, const std::string& name);
nlohmann::json to_json(const MouthParams& p);

}  // namespace ofl
