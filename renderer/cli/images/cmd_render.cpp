// `oralfluor render scene.json -o out/`: renders the scene and writes out/radiance.exr (spectral
// layout), out/preview.png (sRGB through CIE XYZ, auto-exposed) and out/render.json (statistics).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "renderer/camera/raw/camera_color.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/core/files/atomic_file.h"
#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/process/progress.h"
#include "renderer/image/png_writer.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/render/render_job.h"

namespace ofl {

namespace {

// The fluorescent part of the radiance alone, auto-exposed on its own (under violet light it is a
// few per cent of the reflected light and invisible in preview.png).
std::filesystem::path write_fluorescence_preview(const SpectralImage& img, const std::filesystem::path& out) {
  SpectralImage fl;
  fl.resize(img.width, img.height, img.band_nm);
  fl.data = img.fluorescence;
  auto rgb = spectral_to_linear_srgb(fl, 1.0);
  auto file = out / "preview_fluorescence.png";
  write_srgb_png(file, img.width, img.height, rgb, auto_exposure(rgb));
  return file;
}

// What the camera records (noise off), demosaiced to sRGB as `oralfluor camera` previews it.
std::filesystem::path write_camera_preview(const SpectralImage& img, const CameraDescription& cam,
                                           const std::filesystem::path& out, const std::string& scene) {
  CameraRunOptions opt;
  opt.noise = false;
  CameraRun run = simulate_camera(img, cam, opt, scene);
  for (auto& w : run.warnings) std::fprintf(stderr, "warning: camera preview: %s\n", w.c_str());
  CameraColor color = camera_color(run.camera, img.band_lo().front(), img.band_hi().back(), false);
  auto file = out / "preview_camera.png";
  write_raw_preview_png(file, run.raw.dn, run.meta.width, run.meta.height, run.meta.cfa, run.meta.black_level_dn,
                        run.meta.white_level_dn, color, opt.preview);
  return file;
}

}  // namespace

void register_render_command(CLI::App& app) {
  struct Opts {
    std::string scene, out = "out";
    std::optional<int> spp, width, height;
    std::optional<uint64_t> seed;
    std::string camera;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("render", "render a scene file to a spectral radiance EXR and a preview PNG");
  cmd->add_option("scene", o->scene, "scene file (JSON)")->required();
  cmd->add_option("-o,--out", o->out, "output folder (created)");
  cmd->add_option("--spp", o->spp, "samples per pixel (overrides the scene)")->check(CLI::Range(1, 1 << 24));
  cmd->add_option("--seed", o->seed, "random seed (overrides the scene)")->check(uint64_validator());
  cmd->add_option("--width", o->width, "image width (overrides the scene)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", o->height, "image height (overrides the scene)")->check(CLI::Range(1, 16384));
  cmd->add_option("--camera", o->camera, "also write preview_camera.png: the image through this camera (noise off)");
  cmd->add_flag("--json", o->json, "print statistics as JSON");
  cmd->callback([o] {
    SceneOverrides ov{o->spp, o->seed, o->width, o->height};
    auto tl = std::chrono::steady_clock::now();
    Scene scene = load_scene(o->scene, ov);
    double load_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - tl).count();
    throw_if_interrupted("loading the scene; nothing was rendered");
    std::filesystem::path out = o->out;
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    if (ec) throw InputError(out.string(), "", "cannot create output folder: " + ec.message());

    std::vector<std::string> warnings;
    if (auto w = led_band_warning(scene); !w.empty()) warnings.push_back(w);
    for (auto& w : warnings) std::fprintf(stderr, "warning: %s: %s\n", scene.file.c_str(), w.c_str());
    RenderResult r = render(scene);
    write_spectral_exr(out / "radiance.exr", r.image);
    auto rgb = spectral_to_linear_srgb(r.image, 1.0);
    write_srgb_png(out / "preview.png", r.image.width, r.image.height, rgb, auto_exposure(rgb));
    std::vector<std::string> previews = {(out / "preview.png").string()};
    if (!r.image.fluorescence.empty()) previews.push_back(write_fluorescence_preview(r.image, out).string());
    if (!o->camera.empty()) previews.push_back(write_camera_preview(r.image, load_camera(o->camera), out, o->scene).string());

    const auto& s = r.stats;
    std::vector<std::string> all_warnings = warnings;
    all_warnings.insert(all_warnings.end(), s.warnings.begin(), s.warnings.end());
    size_t tris = 0;
    for (auto& m : scene.meshes) tris += m.triangle_count();
    nlohmann::json j = {{"scene", scene.file},
                        {"width", scene.camera.width},
                        {"height", scene.camera.height},
                        {"spp", s.spp_done},
                        {"spp_requested", scene.integrator.spp},
                        {"interrupted", s.interrupted},
                        {"triangles", tris},
                        {"lights", scene.lights.size()},
                        {"wavelength_lanes", kLanes},
                        {"load_seconds", load_s},
                        {"build_seconds", s.build_seconds},
                        {"render_seconds", s.seconds},
                        {"camera_samples_per_second", s.samples_per_second()},
                        {"wavelength_samples_per_second", s.samples_per_second() * kLanes},
                        {"rays", s.rays.total()},
                        {"camera_rays", s.rays.camera},
                        {"extension_rays", s.rays.extension},
                        {"shadow_rays", s.rays.shadow},
                        {"probe_rays", s.rays.probe},
                        {"rays_per_second", s.rays_per_second()},
                        {"relative_noise", s.relative_noise},
                        {"radiance_exr", (out / "radiance.exr").string()},
                        {"preview_png", (out / "preview.png").string()},
                        {"previews", previews},
                        {"warnings", all_warnings}};
    for (const auto& w : s.warnings) std::fprintf(stderr, "warning: %s: %s\n", scene.file.c_str(), w.c_str());
    write_file_atomic(out / "render.json", j.dump(2) + "\n");
    if (o->json) {
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      std::printf("rendered %dx%d at %d spp in %.2f s (+%.2f s load, %.2f s build): %.3f M camera samples/s, %.2f M wavelength samples/s, %.2f M rays/s\n",
                  scene.camera.width, scene.camera.height, s.spp_done, s.seconds, load_s, s.build_seconds,
                  s.samples_per_second() * 1e-6, s.samples_per_second() * kLanes * 1e-6, s.rays_per_second() * 1e-6);
      std::string list;
      for (auto& p : previews) list += (list.empty() ? "" : ", ") + p;
      std::printf("wrote %s and %s\n", (out / "radiance.exr").c_str(), list.c_str());
    }
    if (s.interrupted)
      throw Interrupted("saved " + std::to_string(s.spp_done) + " of " + std::to_string(scene.integrator.spp) +
                        " samples per pixel to " + (out / "radiance.exr").string());
  });
}

}  // namespace ofl
