// Raw mosaic files: a 16-bit single-channel TIFF written through OpenImageIO (the CFA pattern,
// black and white level, exposure and gains in its ImageDescription as JSON), a raw.json sidecar
// with the same numbers plus the camera description, the radiance EXR's oralfluor.* attributes and
// the field geometry (what `oralfluor chroma` reads), and an Adobe DNG 1.4 (CFA, uncompressed) so
// that ordinary raw tools (dcraw, darktable, RawTherapee) open the same mosaic.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/camera/elements/cfa_pattern.h"
#include "renderer/core/files/json_node.h"

namespace ofl {

struct RawMetadata {
  int width = 0, height = 0;
  CfaPattern cfa = CfaPattern::kRGGB;
  int black_level_dn = 0;
  int white_level_dn = 65535;  // brightest value the sensor records (full well or ADC maximum)
  int adc_max_dn = 65535;      // 2^bit_depth - 1
  int bit_depth = 16;
  double exposure_s = 0;
  double f_number = 0;          // lens f-number (DNG FNumber)
  double focal_length_mm = 0;   // 0: unknown (no DNG FocalLength)
  std::string capture_time;     // DNG DateTime (capture_time_text); "" leaves it out
  double system_gain_dn_per_e = 1;  // K at analog gain 1
  double analog_gain = 1;
  double full_well_e = 0;
  bool noise = true;
  uint64_t seed = 0;
  std::string camera_name;
  nlohmann::json extra = nlohmann::json::object();  // camera, exr, field geometry (sidecar only)

  double total_gain() const { return system_gain_dn_per_e * analog_gain; }
  // The numbers (without `extra`), as in the TIFF's ImageDescription.
  nlohmann::json numbers_json() const;
  // numbers_json() plus `extra`: the sidecar.
  nlohmann::json sidecar_json() const;
  static RawMetadata from_json(const JsonNode& node);
};

// "YYYY:MM:DD HH:MM:SS" (TIFF/EXIF DateTime, UTC) of the moment the picture was "taken": the
// modification time of the radiance file the camera ran on (when the scene was rendered), or
// SOURCE_DATE_EPOCH when set; "" when neither is known. Never the time of the camera run itself, so
// the same camera on the same radiance gives the same bytes.
std::string capture_time_text(const std::filesystem::path& radiance_file);

void write_raw_tiff(const std::filesystem::path& file, const std::vector<uint16_t>& dn, const RawMetadata& meta);
void write_raw_sidecar(const std::filesystem::path& file, const RawMetadata& meta);

// Colour data a DNG reader needs: XYZ -> camera matrix (row-major, DNG ColorMatrix1, D65) and the
// camera's response to white (AsShotNeutral, max 1).
struct DngColor {
  std::array<double, 9> xyz_to_camera = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::array<double, 3> as_shot_neutral = {1, 1, 1};
};
void write_dng(const std::filesystem::path& file, const std::vector<uint16_t>& dn, const RawMetadata& meta,
               const DngColor& color);

struct RawImage {
  int width = 0, height = 0;
  std::vector<uint16_t> dn;
  RawMetadata meta;
  nlohmann::json sidecar;                 // the whole sidecar (null when only the TIFF description was found)
  std::filesystem::path sidecar_file;
};
// Reads a raw TIFF and its metadata: the sidecar next to it (same name, .json) when present,
// else the JSON in the TIFF's ImageDescription. InputError for anything else.
RawImage read_raw(const std::filesystem::path& tiff);
std::filesystem::path sidecar_path(const std::filesystem::path& tiff);

}  // namespace ofl
