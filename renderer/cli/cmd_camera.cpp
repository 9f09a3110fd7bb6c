// `oralfluor camera radiance.exr --camera camera.json -o out/`: simulates a camera (lens, filter
// stack, sensor with EMVA 1288 noise) on a spectral radiance EXR and writes raw.tiff + raw.json,
// raw.dng, electrons.exr and camera_preview.png. See docs/camera.md.
#include <cstdio>

#include "renderer/camera/camera_pipeline.h"
#include "renderer/cli/commands.h"
#include "renderer/core/error.h"
#include "renderer/image/spectral_exr.h"

namespace ofl {

void register_camera_command(CLI::App& app) {
  struct Opts {
    std::string radiance, camera, out = "out";
    std::string noise, wb = "sensor", exposure = "auto";
    int64_t seed = -1;
    bool json = false, no_dng = false, strict = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("camera", "simulate a camera on a spectral radiance EXR: raw mosaic, electrons, preview");
  cmd->add_option("radiance", o->radiance, "spectral radiance EXR (Fichet-Pacanowski-Wilkie layout)")->required();
  cmd->add_option("--camera", o->camera, "camera description JSON (see docs/camera.md)")->required();
  cmd->add_option("-o,--out", o->out, "output folder (default: out)");
  cmd->add_option("--seed", o->seed, "temporal noise seed (overrides the camera's)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--noise", o->noise, "on or off (overrides the camera's \"noise\")")->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--wb", o->wb, "preview white balance: sensor (default), gray or none")
      ->check(CLI::IsMember({"sensor", "gray", "grey", "none"}));
  cmd->add_option("--preview-exposure", o->exposure, "auto (default) or raw (white level = 1)")
      ->check(CLI::IsMember({"auto", "raw"}));
  cmd->add_flag("--no-dng", o->no_dng, "do not write raw.dng");
  cmd->add_flag("--strict", o->strict, "refuse (exit 2) when light or camera response lies outside the image's bands");
  cmd->add_flag("--json", o->json, "print a JSON summary on stdout");
  cmd->callback([o] {
    CameraDescription cam = load_camera(o->camera);
    SpectralImage img = read_spectral_exr(o->radiance);
    CameraRunOptions opt;
    if (o->seed >= 0) opt.seed = static_cast<uint64_t>(o->seed);
    if (!o->noise.empty()) opt.noise = o->noise == "on";
    parse_white_balance(o->wb, &opt.preview.white_balance);
    opt.preview.auto_exposure = o->exposure == "auto";
    opt.write_dng = !o->no_dng;
    opt.strict_bands = o->strict;
    std::vector<std::string> input_warnings;
    check_radiance(img, o->radiance, &input_warnings);
    CameraRun run = simulate_camera(img, cam, opt, o->radiance);
    for (auto& w : input_warnings) run.warnings.insert(run.warnings.begin(), w);
    run.summary["warnings"] = run.warnings;
    CameraOutputs out = write_camera_outputs(run, cam, opt, o->out);
    nlohmann::json files = {{"raw_tiff", out.raw_tiff.string()}, {"raw_json", out.raw_json.string()},
                            {"electrons_exr", out.electrons_exr.string()}, {"preview_png", out.preview_png.string()}};
    if (!out.raw_dng.empty()) files["raw_dng"] = out.raw_dng.string();
    run.summary["outputs"] = files;
    for (auto& w : run.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    if (o->json) {
      std::printf("%s\n", run.summary.dump(2).c_str());
      return;
    }
    const auto& s = run.summary;
    std::printf("camera \"%s\" on %s: %dx%d, %zu bands %.1f-%.1f nm, CFA %s, noise %s (seed %llu)\n", cam.name.c_str(),
                o->radiance.c_str(), img.width, img.height, img.band_nm.size(), img.band_lo().front(),
                img.band_hi().back(), cfa_name(cam.sensor.cfa).c_str(), run.meta.noise ? "on" : "off",
                static_cast<unsigned long long>(run.meta.seed));
    std::printf("field angles from %s; corner %.2f deg\n", run.geometry.source_name(),
                s["field_geometry"]["max_field_angle_deg"].get<double>());
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
  });
}

}  // namespace ofl
