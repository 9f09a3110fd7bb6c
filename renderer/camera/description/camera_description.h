// The camera a spectral radiance image is fed to: lens, filter stack and sensor, as read from a
// camera.json file (format below, field by field in docs/camera.md). Plain structs with defaults;
// parse_camera validates every field and names the file and JSON path of anything wrong;
// camera_to_json writes a self-contained copy (spectra inlined as points) that parse_camera reads
// back, which is how raw.json sidecars carry the camera to `oralfluor chroma`.
//
//   {
//     "format": "oralfluor-camera", "version": 1,
//     "name": "oraleye-like",
//     "lens":    { "f_number": 2.4, "focal_length_mm": 3.6, "magnification": 0, "transmittance": 0.92,
//                  "cos4": true, "sensor_cra_deg": 25 },
//     "filters": [ { "type": "longpass", "edge_nm": 475, "width_nm": 8, "od": 4, "position": "front" } ],
//     "sensor":  { "pixel_pitch_um": 3.0, "cfa": "RGGB",
//                  "qe": { "file": "qe.csv", "columns": { "R": "r", "G": "g", "B": "b" } },
//                  "exposure_s": 0.033, "system_gain_dn_per_e": 0.25, "full_well_e": 10000, ... },
//     "optics":  { "sensor_pixels": [1280, 800], "focus_distance_mm": 40 },   (optional, optics_description.h)
//     "noise": true,
//     "seed": 1
//   }
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "renderer/camera/description/optics_description.h"
#include "renderer/camera/elements/cfa_pattern.h"
#include "renderer/camera/elements/filter_stack.h"
#include "renderer/core/files/json_node.h"
#include "renderer/spectral/spectra/spectrum.h"

namespace ofl {

struct LensDescription {
  double f_number = 2.8;          // "f_number": N (> 0). Sensor irradiance E = pi T L / (1 + 4 N^2 (1 - m)^2).
  double focal_length_mm = 0;     // "focal_length_mm": f; with the pixel pitch it sets each pixel's field
                                  //   angle. 0 (absent): field angles come from the EXR's oralfluor.vfov_deg.
  double magnification = 0;       // "magnification": m <= 0 (real, inverted image; ISETCam sign convention).
                                  //   0 = object at infinity. Working f-number N (1 - m).
  Spectrum transmittance = constant_spectrum(1.0);  // "transmittance": lens spectral transmittance T (0..1).
  bool cos4 = true;               // "cos4": natural vignetting, irradiance times cos^4(field angle).
  double sensor_cra_deg = -1;     // "sensor_cra_deg": image-side chief-ray angle at the sensor corner
                                  //   (datasheet "max CRA"), growing linearly in tan with image height; used
                                  //   for filters at the sensor. Absent: equal to the field angle (thin lens,
                                  //   stop at the lens).
};

struct SensorDescription {
  double pixel_pitch_um = 3.0;    // "pixel_pitch_um": pixel pitch (square pixels); A_pixel = pitch^2.
  double fill_factor = 1.0;       // "fill_factor": light-collecting fraction of the pixel (0..1]; microlens
                                  //   gain folded in.
  CfaPattern cfa = CfaPattern::kRGGB;  // "cfa": "RGGB", "GRBG", "GBRG" or "BGGR" (top-left 2x2 cell, row by row).
  std::array<Spectrum, 3> qe = {constant_spectrum(0.5), constant_spectrum(0.5), constant_spectrum(0.5)};
                                  // "qe": quantum efficiency (electrons per photon, 0..1) of the R, G, B
                                  //   pixels, colour filter included: {"file", "columns", "scale"} or
                                  //   {"R": spectrum, "G": spectrum, "B": spectrum}.
  std::string qe_source = "constant 0.5";
  double exposure_s = 0.01;       // "exposure_s": integration time t.
  double system_gain_dn_per_e = 0.25;  // "system_gain_dn_per_e": K at analog gain 1 (EMVA 1288 "overall system
                                  //   gain"); or "conversion_gain_uV_per_e" with "adc_uV_per_dn" (K = ratio).
  double analog_gain = 1.0;       // "analog_gain": multiplies K (the ISO setting). Total gain K * analog_gain.
  double full_well_e = 10000;     // "full_well_e": saturation capacity; the electron count is clipped here.
  double read_noise_e = 2.0;      // "read_noise_e": temporal dark noise sigma_d (Gaussian, electrons rms).
  double dark_current_e_per_s = 0;     // "dark_current_e_per_s": mean dark current at the reference temperature.
  double dark_reference_C = 25;   // "dark_current_reference_C": temperature the dark current was given at.
  double temperature_C = 25;      // "temperature_C": sensor temperature (default: the reference).
  double dark_doubling_C = 6.0;   // "dark_current_doubling_C": dark current doubles every this many degrees.
  double dsnu_e = 0;              // "dsnu_e": dark signal non-uniformity, std. dev. of a fixed per-pixel
                                  //   offset in electrons (independent of exposure).
  double prnu = 0;                // "prnu_percent" / 100: photo-response non-uniformity, std. dev. of a fixed
                                  //   per-pixel gain on the expected photo-electrons.
  int black_level_dn = 64;        // "black_level_dn": offset added after quantisation.
  int bit_depth = 12;             // "bit_depth": ADC bits (8..16); raw values are clipped to [0, 2^bits - 1].
  uint64_t fixed_pattern_seed = 1;  // "fixed_pattern_seed": seeds PRNU and DSNU (a property of the sensor, the
                                  //   same for every frame; the temporal noise uses the camera "seed").

  double total_gain() const { return system_gain_dn_per_e * analog_gain; }
  int adc_max_dn() const { return (1 << bit_depth) - 1; }
  // Dark current at temperature_C in electrons per second.
  double dark_current_at_temperature() const;
  // Expected dark electrons in one exposure.
  double dark_electrons() const { return dark_current_at_temperature() * exposure_s; }
  // Raw value of a pixel clipped at full well (the brightest value the sensor records), at most the ADC maximum.
  int white_level_dn() const;
  double pixel_area_m2() const { return pixel_pitch_um * pixel_pitch_um * 1e-12; }
};

struct CameraDescription {
  std::string name = "camera";    // "name": free text, written to the raw metadata.
  LensDescription lens;           // "lens"
  FilterStack filters;            // "filters": array of filters (spectrum_json.h filter forms, or
                                  //   {"type": "measured", "points": [[nm, T], ...]}) with "position":
                                  //   "front" (default, in front of the lens) or "sensor".
  SensorDescription sensor;       // "sensor"
  OpticsDescription optics;       // "optics": the optical-image stage (own sensor grid, PSF); absent: the
                                  //   sensor grid is the image's grid and there is no blur (optics.h)
  bool noise = true;              // "noise": false gives the noise-free raw (expected values, no fixed pattern).
  uint64_t seed = 1;              // "seed": temporal noise; the same seed gives the same raw at any thread count.
  std::string source;             // the file it was read from (not serialised)
};

// Reads a camera.json file (relative data paths resolve against its folder), or an ISETCam sensor
// .mat (renderer/formats/iset_sensor.h).
CameraDescription load_camera(const std::filesystem::path& file);
// Parses a camera object (the root of a camera.json, or the "camera" member of a raw.json sidecar).
CameraDescription parse_camera(const JsonNode& node);
// A self-contained camera object: spectra sampled at their table wavelengths and every nm over
// [lo_nm, hi_nm] (the range the camera is used over), parametric filters kept parametric.
nlohmann::json camera_to_json(const CameraDescription& cam, double lo_nm, double hi_nm);

// A spectrum as {"type": "points", "points": [[nm, v], ...], "outside": "zero"}, sampled at its
// kinks (all of them: exact for tables) and every `step_nm` over [lo_nm, hi_nm].
nlohmann::json spectrum_to_points_json(const Spectrum& s, double lo_nm, double hi_nm, double step_nm = 1.0);

}  // namespace ofl
