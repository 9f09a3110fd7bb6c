// `oralfluor camera` as a library call: spectral radiance + camera description -> field geometry,
// expected electrons, raw mosaic and its metadata, a summary; and the files the command writes
// (raw.tiff, raw.json, raw.dng, electrons.exr, preview.png).
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/camera/description/camera_description.h"
#include "renderer/camera/optics/lens_optics.h"
#include "renderer/camera/raw/raw_preview.h"
#include "renderer/camera/raw/raw_writer.h"
#include "renderer/camera/sensor/expected_signal.h"
#include "renderer/camera/sensor/sensor_model.h"
#include "renderer/image/spectral_image.h"

namespace ofl {

struct CameraRunOptions {
  std::optional<uint64_t> seed;  // overrides the camera's "seed"
  std::optional<bool> noise;     // overrides the camera's "noise"
  PreviewSettings preview;
  bool write_dng = true;
  bool strict_bands = false;  // light or response outside the image's bands is an error, not a warning
  std::optional<double> exposure_s;  // overrides the camera's sensor.exposure_s (the start of auto exposure)
  // Auto exposure (as ISETCam's autoExposure): the exposure at which the given percentile of the
  // pixels' expected electrons (photo + dark, noise-free) reaches `auto_target` x full well.
  bool auto_exposure = false;
  double auto_target = 0.8;        // fraction of full well, in (0, 1]
  double auto_percentile = 99.5;   // in (0, 100]
  double exposure_scale = 1.0;     // bracketing: the exposure (fixed or auto) times this
  std::string output_suffix;       // file names get it before the extension (raw<suffix>.tiff ...)
};

// The exposure a run uses: fixed (camera or override) or found by auto exposure; `how` says which.
struct ExposureChoice {
  double exposure_s = 0;
  nlohmann::json how;
};

struct CameraRun {
  FieldGeometry geometry;
  ExpectedSignal expected;
  RawFrame raw;
  RawMetadata meta;
  std::vector<std::string> warnings;
  nlohmann::json summary;  // per-channel means, saturation, geometry, warnings
  CameraDescription camera; // the camera as run (its exposure is the one used)
  ExposureChoice exposure;
};

// "_8.25ms": a file-name suffix naming an exposure (bracketed runs), 4 significant digits.
std::string exposure_suffix(double exposure_s);
// Suffixes for the exposures of one bracket: as exposure_suffix, with as many more significant
// digits as it takes for every exposure to get its own name (33 ms and 33.00033 ms: "_33ms" and
// "_33.00033ms", not "_33ms" twice). Exposures must be distinct (the caller refuses repeats).
std::vector<std::string> exposure_suffixes(const std::vector<double>& exposures_s);

// Warnings for light the image cannot hold: the camera's response outside its bands, and the
// share of the recorded LED spectrum (oralfluor.excitation_spd) outside them, naming the range.
// A malformed attribute goes to `notes`.
std::vector<std::string> lost_light_warnings(const SpectralImage& radiance, const CameraDescription& cam,
                                             std::vector<std::string>* notes);

// The field geometry of the image the sensor sees (the radiance, or the optical image when the
// camera has an "optics" section): field and sensor angles per pixel, with the optical axis at the
// offset the optics stage reports (0, 0 without it) and the sensor's chief-ray angle given at the
// farthest corner. simulate_camera and the ISETCam optical-image export use it alike.
FieldGeometry sensor_field_geometry(const SpectralImage& img, const CameraDescription& cam, double axis_x_px, double axis_y_px,
                                    std::vector<std::string>* warnings);

CameraRun simulate_camera(const SpectralImage& radiance, const CameraDescription& cam, const CameraRunOptions& opt,
                          const std::string& radiance_file);

struct CameraOutputs {
  std::filesystem::path raw_tiff, raw_json, raw_dng, electrons_exr, preview_png;
};
CameraOutputs write_camera_outputs(const CameraRun& run, const CameraDescription& cam, const CameraRunOptions& opt,
                                   const std::filesystem::path& dir);

// Expected electrons as a float EXR: channels R, G, B (photo-electrons each channel would collect)
// and "mosaic" (the pixel's own channel plus the expected dark electrons).
void write_electrons_exr(const std::filesystem::path& file, const ExpectedSignal& e, const nlohmann::json& attributes);

}  // namespace ofl
