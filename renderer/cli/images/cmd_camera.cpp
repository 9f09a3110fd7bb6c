// `oralfluor camera radiance.exr --camera camera.json -o out/`: simulates a camera (lens, filter
// stack, sensor with EMVA 1288 noise) on a spectral radiance EXR and writes raw.tiff + raw.json,
// raw.dng, electrons.exr and camera_preview.png. See docs/camera.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <vector>

#include "renderer/camera/camera_pipeline.h"
#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/process/progress.h"
#include "renderer/image/spectral_exr.h"

namespace ofl {

namespace {

// One line on what the optical-image stage did.
void print_optics(const nlohmann::json& o, const CameraDescription& cam) {
  size_t largest = 1;
  for (const auto& l : o["depth_layers"])
    largest = std::max<size_t>(largest, l["kernel_size_px_first_band"].get<size_t>());
  std::printf("optics: sensor %dx%d at %.3g um (a render pixel is %.3g sensor pixels), PSF %s at working f/%.3g, "
              "%zu depth layer(s), largest kernel %zux%zu render pixels, %zu pixels without data, %zu partly covered\n",
              o["sensor_pixels"][0].get<int>(), o["sensor_pixels"][1].get<int>(), cam.sensor.pixel_pitch_um,
              1.0 / o["render_pixels_per_sensor_pixel"].get<double>(), o["psf"].get<std::string>().c_str(),
              o["working_f_number"].get<double>(), o["depth_layers"].size(), largest, largest,
              o["pixels_without_data"].get<size_t>(), o["pixels_partly_covered"].get<size_t>());
}

void print_camera_run(const CameraRun& run, const CameraOutputs& out, const CameraDescription& cam,
                      const SpectralImage& img, const std::string& radiance) {
  const auto& s = run.summary;
  std::printf("camera \"%s\" on %s: %dx%d, %zu bands %.1f-%.1f nm, CFA %s, noise %s (seed %llu)\n", cam.name.c_str(),
              radiance.c_str(), img.width, img.height, img.band_nm.size(), img.band_lo().front(), img.band_hi().back(),
              cfa_name(cam.sensor.cfa).c_str(), run.meta.noise ? "on" : "off", static_cast<unsigned long long>(run.meta.seed));
  std::printf("exposure %.6g s (%s); field angles from %s; corner %.2f deg\n", run.exposure.exposure_s,
              run.exposure.how.value("mode", "").c_str(), run.geometry.source_name(),
              s["field_geometry"]["max_field_angle_deg"].get<double>());
  if (s.contains("optics")) print_optics(s["optics"], cam);
  std::printf("%-8s %16s %12s %14s %11s\n", "channel", "mean electrons", "mean DN", "DN - black", "saturated");
  for (const char* c : {"R", "G", "B"}) {
    const auto& ch = s["channels"][c];
    std::printf("%-8s %16.2f %12.2f %14.2f %10.3f%%\n", c, ch["mean_expected_electrons"].get<double>(),
                ch["mean_dn"].get<double>(), ch["mean_dn_above_black"].get<double>(),
                100.0 * ch["saturated_fraction"].get<double>());
  }
  std::printf("wrote %s, %s,%s %s, %s\n", out.raw_tiff.string().c_str(), out.raw_json.string().c_str(),
              out.raw_dng.empty() ? "" : (" " + out.raw_dng.string() + ",").c_str(), out.electrons_exr.string().c_str(),
              out.preview_png.string().c_str());
}

// --bracket: every factor a finite number in range (the option's validator) and no factor twice,
// since two runs at one exposure would write the same files.
void check_bracket_factors(const std::vector<double>& factors) {
  for (size_t i = 0; i < factors.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (factors[i] == factors[j])
        throw InputError("", "--bracket", "factor " + std::to_string(i + 1) + " repeats factor " + std::to_string(j + 1) + " (" +
                                              nlohmann::json(factors[i]).dump() + "): each exposure is simulated and written once");
}

}  // namespace

void register_camera_command(CLI::App& app) {
  struct Opts {
    std::string radiance, camera, out = "out";
    std::string noise, wb = "sensor", exposure = "auto", sensor_exposure;
    double target = 0.8, percentile = 99.5;
    std::vector<double> bracket;
    std::optional<uint64_t> seed;
    bool json = false, no_dng = false, strict = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("camera", "simulate a camera on a spectral radiance EXR: raw mosaic, electrons, preview");
  cmd->add_option("radiance", o->radiance, "spectral radiance EXR (Fichet-Pacanowski-Wilkie layout)")->required();
  cmd->add_option("--camera", o->camera, "camera description JSON (see docs/camera.md)")->required();
  cmd->add_option("-o,--out", o->out, "output folder (default: out)");
  cmd->add_option("--seed", o->seed, "temporal noise seed (overrides the camera's)")->check(uint64_validator());
  cmd->add_option("--noise", o->noise, "on or off (overrides the camera's \"noise\")")->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--wb", o->wb, "preview white balance: sensor (default), gray or none")
      ->check(CLI::IsMember({"sensor", "gray", "grey", "none"}));
  cmd->add_option("--preview-exposure", o->exposure, "auto (default) or raw (white level = 1)")
      ->check(CLI::IsMember({"auto", "raw"}));
  cmd->add_option("--exposure", o->sensor_exposure,
                  "sensor exposure: seconds (overrides the camera's sensor.exposure_s) or \"auto\" (see --exposure-target)");
  cmd->add_option("--exposure-target", o->target, "auto exposure: fraction of full well the percentile pixel reaches (default 0.8)")
      ->check(finite_range(0.001, 1.0));
  cmd->add_option("--exposure-percentile", o->percentile, "auto exposure: which pixel, as a percentile of expected electrons (default 99.5)")
      ->check(finite_range(0.001, 100.0));
  cmd->add_option("--bracket", o->bracket, "exposure bracketing: factors of the exposure, e.g. 0.25,1,4; files named by exposure (raw_8.25ms.tiff ...)")
      ->delimiter(',')
      ->check(finite_range(1e-6, 1e6));
  cmd->add_flag("--no-dng", o->no_dng, "do not write raw.dng");
  cmd->add_flag("--strict", o->strict, "refuse (exit 2) when light or camera response lies outside the image's bands");
  cmd->add_flag("--json", o->json, "print a JSON summary on stdout");
  cmd->callback([o] {
    CameraDescription cam = load_camera(o->camera);
    SpectralImage img = read_spectral_exr(o->radiance);
    throw_if_interrupted("reading the radiance; nothing was written");
    CameraRunOptions opt;
    if (o->seed) opt.seed = *o->seed;
    if (!o->noise.empty()) opt.noise = o->noise == "on";
    parse_white_balance(o->wb, &opt.preview.white_balance);
    opt.preview.auto_exposure = o->exposure == "auto";
    opt.write_dng = !o->no_dng;
    opt.strict_bands = o->strict;
    if (o->sensor_exposure == "auto") {
      opt.auto_exposure = true;
    } else if (!o->sensor_exposure.empty()) {
      char* end = nullptr;
      double t = std::strtod(o->sensor_exposure.c_str(), &end);
      if (end == o->sensor_exposure.c_str() || *end != 0 || !(t > 0) || !std::isfinite(t))
        throw InputError("", "--exposure", "expected seconds > 0 or \"auto\" (got \"" + o->sensor_exposure + "\")");
      opt.exposure_s = t;
    }
    opt.auto_target = o->target;
    opt.auto_percentile = o->percentile;
    std::vector<double> factors = o->bracket.empty() ? std::vector<double>{1.0} : o->bracket;
    check_bracket_factors(factors);
    std::vector<std::string> input_warnings;
    check_radiance(img, o->radiance, &input_warnings);
    nlohmann::json brackets = nlohmann::json::array();
    std::vector<std::string> suffixes;
    for (size_t i = 0; i < factors.size(); ++i) {
      CameraRunOptions ok = opt;
      ok.exposure_scale = factors[i];
      CameraRun run = simulate_camera(img, cam, ok, o->radiance);
      // Every exposure of the bracket is the first one's times its factor: name them all at once,
      // with the digits it takes to keep the names apart.
      if (!o->bracket.empty() && i == 0) {
        std::vector<double> exposures;
        for (double f : factors) exposures.push_back(run.exposure.exposure_s / factors[0] * f);
        suffixes = exposure_suffixes(exposures);
      }
      if (!o->bracket.empty()) ok.output_suffix = suffixes[i];
      for (auto& w : input_warnings) run.warnings.insert(run.warnings.begin(), w);
      run.summary["warnings"] = run.warnings;
      CameraOutputs out = write_camera_outputs(run, run.camera, ok, o->out);
      nlohmann::json files = {{"raw_tiff", out.raw_tiff.string()}, {"raw_json", out.raw_json.string()},
                              {"electrons_exr", out.electrons_exr.string()}, {"preview_png", out.preview_png.string()}};
      if (!out.raw_dng.empty()) files["raw_dng"] = out.raw_dng.string();
      run.summary["outputs"] = files;
      if (i == 0)
        for (auto& w : run.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
      brackets.push_back(run.summary);
      if (o->json) continue;
      print_camera_run(run, out, cam, img, o->radiance);
    }
    if (o->json) std::printf("%s\n", (o->bracket.empty() ? brackets[0] : nlohmann::json{{"brackets", brackets}}).dump(2).c_str());
  });
}

}  // namespace ofl
