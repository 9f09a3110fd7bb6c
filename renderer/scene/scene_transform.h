// The "transform" object of scene-file geometry: translate / rotate_deg / scale, or a matrix.
#pragma once
#include <glm/mat4x4.hpp>

#include "renderer/core/files/json_node.h"

namespace ofl {

// {"translate": [x,y,z], "rotate_deg": [rx, ry, rz] (applied x then y then z),
//  "scale": s | [sx, sy, sz]} or {"matrix": [16 numbers, column-major]}.
glm::dmat4 parse_transform(const JsonNode& node);

}  // namespace ofl
