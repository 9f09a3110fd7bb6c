// Grayscale texture maps (concentration or reflectance scale maps) read with OpenImageIO and
// looked up bilinearly in UV space (u right, v up as in glTF after flipping rows, repeat wrap).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace ofl {

struct Texture {
  std::string file;
  int width = 0, height = 0;
  std::vector<float> texels;  // row 0 = top of the image, values as stored (0..1 for 8/16-bit)
  float lookup(float u, float v) const;
};

// Per texel, the distance in texels from its centre to the nearest texel centre on the other side of
// `threshold` (above it against at or below it, compared in double as `lookup`'s callers compare),
// with the texture's repeat wrap; infinite where every texel is on one side. A texel within float
// rounding of the threshold counts as on both sides (distance 0 to it from either), since the
// bilinear look-up's rounding may put points beside it on either side. The exact Euclidean distance transform, two separable passes of the
// lower envelope of parabolas (Felzenszwalb & Huttenlocher, Theory of Computing 8, 415 (2012)).
// A bound for `lookup`: its bilinear value at a point differs in side from texel t's only if a
// corner of the point's cell does, so the side cannot change within distance(t) - 1.5 sqrt 2
// texels of any point whose nearest texel is t (docs/layered-tissue.md, "The volume walk").
std::vector<float> side_distance_texels(const Texture& t, double threshold);

// Reads the first channel (or the luminance of RGB); throws InputError naming the file.
Texture read_texture(const std::filesystem::path& file);

}  // namespace ofl
