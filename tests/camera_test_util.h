// Helpers shared by the camera and chromaticity tests: synthetic radiance images, small cameras
// with analytic (box) quantum efficiencies, a scratch folder and running the CLI.
#pragma once
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include "renderer/analysis/fluorescence_chart.h"
#include "renderer/camera/description/camera_description.h"
#include "renderer/image/spectral_image.h"

namespace ofl::testing {

// A fresh empty folder of this process under the system temp directory (with the process id: two
// test runs on one machine, or two tests of one run in parallel processes, never share one).
inline std::filesystem::path scratch(const std::string& name) {
  auto p = std::filesystem::temp_directory_path() / ("ofl_camera_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

inline std::vector<double> bands(double lo, double hi, double step) {
  std::vector<double> b;
  for (double nm = lo; nm <= hi + 1e-9; nm += step) b.push_back(nm);
  return b;
}

// Radiance `L` W sr^-1 m^-2 nm^-1 in every band of every pixel.
inline SpectralImage uniform_image(int w, int h, const std::vector<double>& band_nm, double L) {
  SpectralImage img;
  img.resize(w, h, band_nm);
  for (auto& v : img.data) v = static_cast<float>(L);
  return img;
}

// A points spectrum equal to `v` on [a, b] and zero outside: a box.
inline Spectrum box(double a, double b, double v) {
  return table_spectrum(TabulatedSpectrum{{a, b}, {v, v}, Outside::kZero}, "box");
}

// Camera with box QEs R 0.6 on 600-700, G 0.5 on 500-600, B 0.4 on 400-500 nm, no filters, no
// noise sources but what the test sets.
inline CameraDescription box_camera() {
  CameraDescription c;
  c.name = "box";
  c.lens.f_number = 2.8;
  c.lens.cos4 = false;
  c.sensor.pixel_pitch_um = 3.0;
  c.sensor.fill_factor = 1.0;
  c.sensor.qe = {box(600, 700, 0.6), box(500, 600, 0.5), box(400, 500, 0.4)};
  c.sensor.exposure_s = 0.01;
  c.sensor.system_gain_dn_per_e = 0.25;
  c.sensor.full_well_e = 1e6;
  c.sensor.read_noise_e = 0;
  c.sensor.black_level_dn = 64;
  c.sensor.bit_depth = 16;
  c.noise = false;
  return c;
}

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

// Runs `oralfluor <args>` and captures stdout and stderr.
inline CommandResult run_oralfluor(const std::string& args, const std::filesystem::path& dir) {
  auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  std::string cmd = std::string(OFL_BINARY) + " " + args + " > " + out.string() + " 2> " + err.string();
  int status = std::system(cmd.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto slurp = [](const std::filesystem::path& p) {
    std::string s;
    if (FILE* f = std::fopen(p.c_str(), "rb")) {
      char buf[4096];
      size_t n;
      while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
      std::fclose(f);
    }
    return s;
  };
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// A small fluorescence chart (FAD and protoporphyrin at three concentrations on tongue
// reflectance, 16 px patches, the example 385 nm LED) shared by the camera CLI and chroma tests.
inline ChartOptions small_chart_options() {
  ChartOptions o;
  o.fluorophores = {"FAD", "protoporphyrin"};
  o.concentrations = {0.0, 2e-3, 1e-2};
  o.patch_px = 16;
  o.peak_irradiance = 4.0;
  o.led = example_led_spectrum();
  o.reflectance = tongue_reflectance_spectrum();
  return o;
}

}  // namespace ofl::testing
