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

// Reads the first channel (or the luminance of RGB); throws InputError naming the file.
Texture read_texture(const std::filesystem::path& file);

}  // namespace ofl
