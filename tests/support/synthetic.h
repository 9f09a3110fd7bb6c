// Synthetic measurements with a known model and one hidden effect, for the hidden-effect tests,
// the detection benchmark and the shipped camera example. The data come from the same forward
// model the diagnosis fits, with random compositions, location-to-location differences,
// realistic noise and (optionally) one candidate cause of random magnitude switched on.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "renderer/diagnose/camera/camera_model.h"
#include "renderer/diagnose/spectra/forward_model.h"

namespace ofl {

struct SyntheticSpectraOptions {
  uint64_t seed = 1;
  std::string effect;            // "" (none) or a spectra candidate name (model_extensions.h)
  std::string extra_fluorophore; // for effect "extra_fluorophore" ("" = random from the candidates)
  double magnitude = -1;         // >= 0: this value instead of a random one for one-parameter
                                 // effects (shift: +value; leak: the OD; extra: its share)
  int subjects = 4;
  std::vector<std::string> sites = {"lip", "tongue"};
  int locations = 2;             // replicates: same condition, another spot (composition jitter)
  double step_nm = 4, min_nm = 380, max_nm = 780;
  double fit_min_nm = 400, fit_max_nm = 740;
  // The data are made on a 1 nm grid and sampled every step_nm; the diagnosis models on a 2 nm
  // grid: a small discretisation mismatch, as real data always have some.
  double generation_step_nm = 1;
  double model_step_nm = 2;
  double noise_relative = 0.01;  // shot-like: sigma = r sqrt(y * mean) + f * mean
  double noise_floor = 0.002;
  double location_jitter = 0.05; // lognormal sigma of each fluorophore share between locations
};

struct SyntheticData {
  std::string effect_id;                 // candidate id of the hidden effect ("" = none)
  std::map<std::string, double> truth;   // its parameters (as reported by diagnose)
};

struct SyntheticSpectra : SyntheticData {
  SpectraSet data;
  SpectraModel model;
};

// The model the synthetic spectra assume (shipped LED and leak spectra of oe_tongue_lip, five
// baseline fluorophores, chlorophyll_a/elastin/teeth as extra candidates, 475 nm long-pass).
SpectraModel synthetic_spectra_model(const SyntheticSpectraOptions& o);
SyntheticSpectra make_synthetic_spectra(const SyntheticSpectraOptions& o);
// Replicate and group columns matching the synthetic conditions.
std::vector<std::string> synthetic_spectra_replicates();

struct SyntheticCameraOptions {
  uint64_t seed = 1;
  std::string effect;            // "" or a camera candidate name
  int captures = 2;              // replicate captures of every patch
  double conversion_gain = 0.25; // DN per electron
  double read_noise_dn = 3;
  double n_pixels = 400;         // pixels averaged per patch
  double capture_jitter = 0.003; // relative light change on a patch between captures
  double full_scale = 4095;
};

struct SyntheticCamera : SyntheticData {
  CameraPatchSet data;
  CameraModel model;
};

// The tolerance within which the hidden-effect tests and the benchmark require a recovered
// parameter (docs/diagnose.md states the same):
//   blood_absorption oxy/deoxy: max(25 %, 1 umol/L*cm); extra_fluorophore share: 30 %;
//   wavelength_shift: 0.25 nm; bandwidth, emission_broadening, stray_light: 20 %;
//   longpass_leak effective OD: 0.15; longpass_edge: 0.5 nm; channel_gain: 0.02;
//   crosstalk: 0.015 per fraction; offset: 5 DN; nonlinearity gamma: 0.015; qe_shift: 1 nm;
//   nir_leak: 25 %.
double stated_tolerance(const std::string& cause_name, double truth);

// MT9V024 QE behind the Largan IR-cut filter (shipped with the camera example).
CameraModel example_camera_model();
// Macbeth chart under 3000 K and 5000 K blackbody light; groups by chart row.
SyntheticCamera make_synthetic_camera(const SyntheticCameraOptions& o);

}  // namespace ofl
