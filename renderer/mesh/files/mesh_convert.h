// `oralfluor mesh convert`: OBJ -> glTF binary with a change of units and axes. The steps, in
// order: read the OBJ; keep only the chosen groups; re-express the axes (a signed permutation,
// e.g. "-z,x,-y" means new x = -old z, new y = old x, new z = -old y); rotate about one of the new
// axes (right-handed, degrees, e.g. "y:19.6"); scale (a fixed factor, or
// the factor that makes the extent along one output axis a target width); optionally centre the
// bounding box on the origin; translate; name the material; merge groups into one mesh.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>

#include "renderer/mesh/files/gltf_writer.h"

namespace ofl {

struct ConvertOptions {
  double scale = 1.0;                  // metres per OBJ unit (ignored when target_width_m is set)
  std::optional<double> target_width_m;  // scale so the extent along width_axis equals this
  int width_axis = 0;                  // 0 = x, 1 = y, 2 = z of the output frame
  std::string axes = "x,y,z";          // output axes as signed input axes
  std::string rotate;                  // "AXIS:DEGREES" about an output axis, after `axes`; empty = none
  bool center = false;                 // centre the bounding box on the origin (before translate)
  glm::dvec3 translate{0.0};           // metres, added last
  std::string material_name;           // replaces every usemtl when set
  bool merge = false;                  // one mesh for all groups (named after the output file)
  std::vector<std::string> groups;     // keep only these OBJ groups/objects (empty = all)
};

struct ConvertReport {
  double scale = 1.0;                  // the factor applied (metres per OBJ unit)
  size_t vertices = 0, triangles = 0, meshes = 0;
  size_t polygons_triangulated = 0;
  glm::dvec3 bounds_min{0.0}, bounds_max{0.0};
  double area_m2 = 0;
};

// Parses an axes spec like "-z,x,-y" into the matrix mapping input to output coordinates.
// Throws InputError(field = "--axes") when it is not a signed permutation of x, y, z.
glm::dmat3 parse_axes(const std::string& spec);

// Parses "y:19.6" into a rotation matrix (right-handed about that axis); InputError(--rotate).
glm::dmat3 parse_rotation(const std::string& spec);

// Converts and returns the document to write (and what was done).
GlbDocument convert_obj(const std::filesystem::path& obj, const ConvertOptions& opt, ConvertReport* report);

}  // namespace ofl
