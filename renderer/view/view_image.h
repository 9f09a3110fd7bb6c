// What `oralfluor view` shows of one file: the per-pixel values (a spectrum, or a camera's R, G, B),
// the fluorescent part when the render kept it, the material plane, and how to turn a pixel into a
// colour. Loaded from a spectral radiance EXR (`oralfluor render`, `import-iset`), from the camera's
// electrons.exr (R, G, B expected electrons) or from its raw.tiff (one R, mean G, B value per 2x2
// CFA cell, above the black level). docs/view.md describes the page.
#pragma once
#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace ofl {

struct ViewImage {
  std::string file;
  std::string kind;                    // "radiance", "electrons" or "raw"
  std::string units;                   // of `values`, e.g. "W sr^-1 m^-2 nm^-1"
  int width = 0, height = 0;           // of the grid `values` is on (raw: CFA cells)
  int pixel_size = 1;                  // source pixels per grid cell side (raw: 2)
  std::vector<double> wavelengths;     // band centres (nm) of a spectral image, else empty
  std::vector<std::string> channels;   // one label per channel ("532.5 nm", "R", ...)
  std::vector<float> values;           // height x width x channels, row-major, channels contiguous
  std::vector<float> fluorescence;     // same layout, or empty
  std::vector<float> material;         // height x width: index into material_names, -1 none, -2 LED; or empty
  std::vector<std::string> material_names;
  // Linear sRGB of a pixel: rgb[k] = sum_c to_rgb[k][c] values[c] (spectral: CIE 1931 through
  // XYZ over the bands; camera channels: the identity), and CIE XYZ likewise (spectral only).
  std::array<std::vector<double>, 3> to_rgb, to_xyz;
  std::vector<std::string> notes;      // what the page should say about this image

  int num_channels() const { return static_cast<int>(channels.size()); }
};

// Reads any of the three kinds, chosen by content (an EXR with R, G, B and mosaic channels is
// electrons.exr; any other EXR must be spectral; .tif/.tiff is a raw mosaic). InputError naming the
// file otherwise.
ViewImage load_view_image(const std::filesystem::path& file);

}  // namespace ofl
