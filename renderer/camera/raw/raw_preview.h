// A viewable picture of a raw mosaic: bilinear demosaicing (each missing colour is the mean of the
// nearest pixels of that colour in the 3x3 neighbourhood), black-level subtraction, white balance,
// camera RGB -> linear sRGB through camera_color's matrix, exposure, sRGB encoding. A preview,
// not a measurement: analysis works on the mosaic itself.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "renderer/camera/elements/cfa_pattern.h"
#include "renderer/camera/raw/camera_color.h"

namespace ofl {

// Demosaiced camera RGB, black subtracted and divided by (white - black): [(y * w + x) * 3 + c].
std::vector<float> demosaic_bilinear(const std::vector<uint16_t>& dn, int width, int height, CfaPattern cfa,
                                     double black, double white);

enum class WhiteBalance {
  kSensor,  // colorimetric for the bare sensor (lens x QE) under D65: the filter stack's colour shows
  kGray,    // gray world: the image's mean becomes neutral, then as kSensor
  kNone     // camera RGB shown as sRGB, no gains, no colour matrix
};
bool parse_white_balance(const std::string& s, WhiteBalance* wb);

struct PreviewSettings {
  WhiteBalance white_balance = WhiteBalance::kSensor;
  bool auto_exposure = true;  // 99th percentile of luminance -> 0.9; else the raw white level -> 1
};

// Linear sRGB preview pixels. `sensor_color` is camera_color(..., include_filters = false).
std::vector<float> raw_to_linear_srgb(const std::vector<uint16_t>& dn, int width, int height, CfaPattern cfa,
                                      double black, double white, const CameraColor& sensor_color,
                                      const PreviewSettings& settings, Vec3* gains_used = nullptr);

void write_raw_preview_png(const std::filesystem::path& file, const std::vector<uint16_t>& dn, int width, int height,
                           CfaPattern cfa, double black, double white, const CameraColor& sensor_color,
                           const PreviewSettings& settings);

}  // namespace ofl
