// A spectral radiance image: width x height pixels, each a spectrum on a set of bands
// (W sr^-1 m^-2 nm^-1, band means). This is the one file the renderer and the camera module share.
#pragma once
#include <map>
#include <string>
#include <vector>

namespace ofl {

struct SpectralImage {
  int width = 0, height = 0;
  std::vector<double> band_nm;   // band centres, increasing
  std::vector<float> data;       // row-major pixels, bands contiguous: ((y * width + x) * bands + b)
  std::map<std::string, std::string> attributes;  // extra header strings (scene, spp, camera...)
  // Optional: the part of the radiance that is fluorescence (same layout as data), written as the
  // EXR layer "fluorescence" (channels fluorescence.S0.<nm>).
  std::vector<float> fluorescence;
  // Optional single-channel planes per pixel ("aov.material", "aov.irradiance", ...).
  std::map<std::string, std::vector<float>> aovs;

  int bands() const { return static_cast<int>(band_nm.size()); }
  float* pixel(int x, int y) { return data.data() + (static_cast<size_t>(y) * width + x) * bands(); }
  const float* pixel(int x, int y) const { return data.data() + (static_cast<size_t>(y) * width + x) * bands(); }
  void resize(int w, int h, std::vector<double> bands_nm) {
    width = w; height = h; band_nm = std::move(bands_nm);
    data.assign(static_cast<size_t>(w) * h * bands(), 0.0f);
  }
  // Band edges implied by the centres (midpoints; the outer bands are symmetric).
  std::vector<double> band_lo() const;
  std::vector<double> band_hi() const;
};

}  // namespace ofl
