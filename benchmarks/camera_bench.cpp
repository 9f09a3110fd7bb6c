// Camera module benchmark and helper.
//   camera_bench                 photon-transfer recovery (EMVA 1288) of K, read noise, full well,
//                                DSNU and PRNU from simulated flat fields, and the camera's speed
//                                (megapixels per second for a 31-band image) as a ratio of the
//                                noise-free to the noisy pipeline.
//   camera_bench chart OUT.exr [patch_px] [peak_irradiance_W_m2_nm] [band_step_nm]
//                                writes the synthetic fluorescence chart used in docs/camera.md.
//   camera_bench psf OUTDIR [f_number] [pitch_um]
//                                writes the lens PSF kernels of the optical-image stage as PNGs
//                                (450 and 650 nm in focus, 550 nm with a 12 um blur circle; each
//                                scaled to its own peak, gamma 0.5 so the rings show) and prints
//                                their sizes and encircled energies (docs/camera.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "renderer/analysis/fluorescence_chart.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/camera/elements/psf.h"
#include "renderer/camera/sensor/photon_transfer.h"
#include "renderer/camera/sensor/sensor_model.h"
#include "renderer/image/image_file.h"
#include "renderer/image/spectral_exr.h"

using namespace ofl;

static int write_chart(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: camera_bench chart OUT.exr [patch_px] [peak_irradiance_W_m2_nm] [band_step_nm]\n");
    return 2;
  }
  ChartOptions o;
  o.fluorophores = {"FAD", "NADH", "collagen", "protoporphyrin", "chlorophyll_a"};
  o.concentrations = {0.0, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2};
  o.patch_px = argc > 3 ? std::atoi(argv[3]) : 40;
  o.peak_irradiance = argc > 4 ? std::atof(argv[4]) : 1.0;
  double step = argc > 5 ? std::atof(argv[5]) : 10.0;
  for (double nm = 400; nm <= 700 + 1e-9; nm += step) o.band_nm.push_back(nm);
  o.led = example_led_spectrum();
  o.reflectance = tongue_reflectance_spectrum();
  o.shading_corner = 0.4;
  SpectralImage img = make_fluorescence_chart(o);
  write_spectral_exr(argv[2], img);
  std::printf("wrote %s: %dx%d, %d bands, rows %zu fluorophores, columns %zu concentrations\n", argv[2], img.width,
              img.height, img.bands(), o.fluorophores.size(), o.concentrations.size());
  return 0;
}

static void ptc() {
  SensorDescription s;
  s.system_gain_dn_per_e = 0.35;
  s.read_noise_e = 4.0;
  s.full_well_e = 40000;
  s.bit_depth = 14;
  s.black_level_dn = 64;
  s.dsnu_e = 3.0;
  s.prnu = 0.01;
  const int w = 256, h = 256;
  FixedPattern fp = make_fixed_pattern(s, w, h);
  auto frame = [&](double mu, uint64_t seed) {
    std::vector<float> e(static_cast<size_t>(w) * h, static_cast<float>(mu));
    return simulate_raw(e, w, h, s, true, seed, fp).dn;
  };
  uint64_t seed = 100;
  FramePair dark{frame(0, seed++), frame(0, seed++)};
  std::vector<FramePair> series;
  for (int k = 1; k <= 80; ++k) {
    double mu = s.full_well_e * 1.15 * k / 80;
    series.push_back({frame(mu, seed++), frame(mu, seed++)});
  }
  auto t0 = std::chrono::steady_clock::now();
  PhotonTransferResult r = analyse_photon_transfer(dark, series);
  std::vector<RawPixels> darks, brights;
  for (int i = 0; i < 16; ++i) {
    darks.push_back(frame(0, seed++));
    brights.push_back(frame(0.5 * s.full_well_e, seed++));
  }
  NonUniformity u = analyse_nonuniformity(darks, brights, r.system_gain_dn_per_e);
  double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("photon transfer, %dx%d flat fields, 80 exposures x 2 frames (EMVA 1288):\n", w, h);
  std::printf("  %-26s %12s %12s %9s\n", "quantity", "set", "recovered", "error");
  auto row = [](const char* n, double set, double got) {
    std::printf("  %-26s %12.5g %12.5g %8.2f%%\n", n, set, got, 100.0 * (got / set - 1.0));
  };
  row("system gain K (DN/e-)", s.system_gain_dn_per_e, r.system_gain_dn_per_e);
  row("read noise (e-)", s.read_noise_e, r.read_noise_e);
  row("saturation capacity (e-)", s.full_well_e, r.saturation_capacity_e);
  row("full well, plateau (e-)", s.full_well_e, r.full_well_plateau_e);
  row("DSNU (e-)", s.dsnu_e, u.dsnu_e);
  row("PRNU (%)", 100 * s.prnu, 100 * u.prnu);
  std::printf("  (%d points in the 0-70%% fit; EMVA saturation capacity = mean at the variance peak, which 1%% PRNU\n"
              "   pulls below the full well; the plateau of fully clipped frames gives the full well itself)\n",
              r.fit_points);
  (void)sec;
}

static void speed() {
  const int w = 1024, h = 1024;
  std::vector<double> bands;
  for (double nm = 400; nm <= 700; nm += 10) bands.push_back(nm);
  SpectralImage img;
  img.resize(w, h, bands);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = 0.01f * (1.0f + 0.5f * std::sin(0.001f * i));
  img.attributes["oralfluor.vfov_deg"] = "50";
  CameraDescription cam;
  cam.sensor.pixel_pitch_um = 3;
  OpticalFilter lp;
  lp.edge_nm = 475;
  cam.filters.filters.push_back({lp, FilterPosition::kFrontOfLens});
  auto time = [&](bool noise) {
    CameraRunOptions o;
    o.noise = noise;
    auto t0 = std::chrono::steady_clock::now();
    CameraRun r = simulate_camera(img, cam, o, "synthetic");
    (void)r;
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  double quiet = time(false), noisy = time(true);
  std::printf("camera pipeline, %dx%d pixels, %zu bands, 475 nm interference long-pass:\n", w, h, bands.size());
  std::printf("  noise off: %.1f Mpixel/s; noise on: %.1f Mpixel/s (noise costs %.2fx)\n", w * h / quiet / 1e6,
              w * h / noisy / 1e6, noisy / quiet);
}

// A kernel as an 8-bit grey PNG, `zoom` x `zoom` screen pixels per kernel pixel, value
// (w / peak)^0.5, cropped to `half` pixels around the centre.
static void write_kernel_png(const std::string& file, const PsfKernel& k, int half, int zoom) {
  int n = 2 * half + 1, size = n * zoom;
  float peak = 0;
  for (float v : k.w) peak = std::max(peak, v);
  std::vector<unsigned char> px(static_cast<size_t>(size) * size, 0);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      int dx = x / zoom - half, dy = y / zoom - half;
      float v = (std::abs(dx) <= k.radius && std::abs(dy) <= k.radius) ? k.at(dx, dy) / peak : 0.0f;
      px[static_cast<size_t>(y) * size + x] = static_cast<unsigned char>(std::lround(255.0 * std::sqrt(std::max(0.0f, v))));
    }
  OIIO::ImageSpec spec(size, size, 1, OIIO::TypeDesc::UINT8);
  write_image_file(file, spec, px.data());
}

static int write_psfs(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: camera_bench psf OUTDIR [f_number] [pitch_um]\n");
    return 2;
  }
  std::string dir = argv[2];
  double N = argc > 3 ? std::atof(argv[3]) : 8.0, pitch = argc > 4 ? std::atof(argv[4]) : 0.5;
  struct Case { const char* name; double nm, blur_um; };
  for (Case c : {Case{"psf_450nm", 450, 0}, Case{"psf_650nm", 650, 0}, Case{"psf_550nm_defocus", 550, 12}}) {
    RadialPsf p = airy_psf(c.nm, N, 15);
    if (c.blur_um > 0) p = defocus_psf(p, c.blur_um);
    PsfKernel k = pixel_kernel(p, pitch, 4, 0.25 * c.nm * 1e-3 * N);
    std::string file = dir + "/" + c.name + ".png";
    write_kernel_png(file, k, 24, 6);
    double ln = c.nm * 1e-3 * N, ring = 1.22 * ln, ee = 0;
    for (int dy = -k.radius; dy <= k.radius; ++dy)
      for (int dx = -k.radius; dx <= k.radius; ++dx)
        if (std::hypot(dx, dy) * pitch <= ring) ee += k.at(dx, dy);
    std::printf("%s: f/%g, %g nm, blur circle %g um, grid %g um, kernel %dx%d, first dark ring %.2f um, "
                "kernel weight within it %.3f; wrote %s\n",
                c.name, N, c.nm, c.blur_um, pitch, k.size(), k.size(), ring, ee, file.c_str());
  }
  return 0;
}

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "chart") return write_chart(argc, argv);
  if (argc > 1 && std::string(argv[1]) == "psf") return write_psfs(argc, argv);
  ptc();
  speed();
  return 0;
}
