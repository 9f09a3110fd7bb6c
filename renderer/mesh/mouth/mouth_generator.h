// The procedural mouth (`oralfluor mesh mouth`): one closed, outward-facing surface for the
// head block, face, lips and oral cavity, split into parts by material, plus an optional
// procedural tongue. Built as rings of `segments` vertices swept from the back of the head
// block, along its sides, over the face plate, around the lip tube, through the vestibule and
// the cavity, to the centre of the flat pharynx wall.
//
// Parts (glTF node name -> material): skin -> skin (head block and face plate), upper_lip and
// lower_lip -> lips, cheek_left and cheek_right -> cheek, palate -> palate, floor -> floor (the
// cavity parts include the vestibule and their share of the pharynx wall), tongue -> tongue.
// Every part has UVs in [0,1] (u across, v front to back) and smooth normals; normals point out
// of the tissue (into the air of the cavity). The parts except the tongue together are
// watertight; the tongue alone is too.
//
// Layout in the mouth frame (see mouth_params.h): the lip tube's centre line lies in x = 0
// (the lower lip's moves back by lower_lip_setback_m); the inner lip edges are at
// z = +-opening_m/2 on the midline; the full cavity section starts at
// x = -(lip_thickness_m/2 + vestibule_depth_m) and ends at the pharynx wall x = -cavity_depth_m;
// the cavity's floor rises linearly from -floor_depth_m to -floor_depth_m + floor_rise_m there.
#pragma once
#include <vector>

#include "renderer/mesh/files/gltf_writer.h"
#include "renderer/mesh/mouth/mouth_params.h"
#include "renderer/mesh/geometry/triangle_mesh.h"

namespace ofl {

struct Mouth {
  std::vector<TriangleMesh> parts;   // skin, lips, cheeks, palate, floor, then tongue if asked
  std::vector<GltfAnchor> anchors;   // see mouth_anchors below
};

// Anchors (empty glTF nodes): opening_center; upper_teeth_slot, lower_teeth_slot, sofa_tongue_slot
// (translations to apply to teeth_upper.glb / teeth_lower.glb (or teeth.glb) / tongue.glb: zero
// at the default parameters, following palate_height_m and floor_depth_m otherwise);
// pharynx_center; and, with the procedural tongue, tongue_tip and tongue_dorsum (its highest point).
Mouth make_mouth(const MouthParams& p);

// The document `oralfluor mesh mouth` writes: parts, anchors, parameters in asset.extras.
GlbDocument mouth_document(const MouthParams& p);

}  // namespace ofl
