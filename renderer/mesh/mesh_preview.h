// A small z-buffer rasteriser for looking at meshes without the path tracer: orthographic or
// perspective views, two-sided Lambert shading under a headlight, one colour per material (the
// glTF writer's hint colours), back faces tinted blue (so inverted normals show), an optional
// clip plane for cut-away sections, and optional grayscale maps overlaid in UV space (to check
// where a texture lands on the tongue). Output is linear RGB for write_srgb_png.
#pragma once
#include <utility>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "renderer/mesh/geometry/triangle_mesh.h"

namespace ofl {

struct PreviewCamera {
  bool perspective = false;
  glm::dvec3 eye{1, 0, 0}, target{0, 0, 0}, up{0, 0, 1};
  double fov_deg = 50;        // vertical, perspective only
  double ortho_height = 0;    // world height of the view, orthographic only; 0 = fit the meshes
};

// A named view of the mouth frame (x out of the mouth, y patient's left, z up): "front"
// (looking in along -x), "side" (from the patient's right, looking along +y), "top" (looking
// down along -z, +x at the bottom of the picture), "iso", or "camera" (perspective, 5 cm in front
// of the lips, the way an intra-oral camera looks in).
PreviewCamera named_view(const std::string& name);

struct ClipPlane {
  int axis = -1;        // -1 = none; 0, 1, 2 = x, y, z
  bool keep_below = true;  // keep points with coordinate < value (else > value)
  double value = 0;
};
// Parses "y<0", "x>0.01" etc.; throws InputError(field = "--clip") otherwise.
ClipPlane parse_clip(const std::string& spec);

struct UvOverlay {
  int width = 0, height = 0;
  std::vector<float> value;  // [0,1], row 0 = v 0 (glTF convention)
  glm::dvec3 color{0.1, 0.9, 0.2};
  double sample(double u, double v) const;  // bilinear, clamped
};
// Reads a grayscale (or first channel of a colour) image as an overlay; InputError if unreadable.
UvOverlay read_overlay(const std::string& file);
// Parses "MATERIAL=file.png" or "MATERIAL=file.png@R,G,B" (colour in 0..1) for --overlay.
std::pair<std::string, UvOverlay> parse_overlay(const std::string& spec);

struct PreviewOptions {
  int width = 512, height = 512;
  ClipPlane clip;
  std::vector<std::pair<std::string, UvOverlay>> overlays;  // (material, map) painted in order
  glm::dvec3 background{0.02, 0.02, 0.03};
};

// Linear RGB, 3 floats per pixel, row 0 at the top.
std::vector<float> render_preview(const std::vector<TriangleMesh>& meshes, PreviewCamera cam, const PreviewOptions& opt);

}  // namespace ofl
