// `oralfluor export-iset radiance.exr -o scene.mat`: writes the spectral radiance as an ISETCam scene
// structure (variable `scene`: photons rows x cols x wave, wave, wAngular, distance, the LED
// illuminant when the render recorded it), ready for ISETCam's sceneGet / oiCompute / sensorCompute.
// With --camera, the camera's optical image instead (variable `oi`: sensor-plane irradiance after the
// lens, filters and optics stage), for ISETCam's own sensorCompute.
// Field by field: renderer/interop/iset_scene.h, renderer/interop/iset_oi.h and docs/matlab.md.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/camera/description/camera_description.h"
#include "renderer/interop/iset_oi.h"
#include "renderer/interop/iset_scene.h"

namespace ofl {
namespace {

template <typename Opts>
void export_oi(const SpectralImage& img, Opts& o) {
  CameraDescription cam = load_camera(o.camera);
  if (o.out.empty()) o.out = "oi.mat";
  IsetOi oi = make_iset_oi(img, cam, o.exr);
  write_iset_oi(o.out, oi);
  for (auto& w : oi.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  nlohmann::json j = {{"file", o.out},          {"kind", "oi"},       {"rows", oi.rows},
                      {"cols", oi.cols},         {"wave_nm", img.band_nm}, {"hfov_deg", oi.hfov_deg},
                      {"focal_length_m", oi.focal_length_m}, {"pixel_pitch_m", oi.pixel_pitch_m},
                      {"photon_sum", oi.photon_sum}, {"warnings", oi.warnings}};
  if (o.json) {
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("wrote %s: ISETCam optical image %dx%d through %s, %d wavelengths, wAngular %.3f deg (one sample per %.3g um pixel)\n",
              o.out.c_str(), oi.rows, oi.cols, cam.name.c_str(), img.bands(), oi.hfov_deg, oi.pixel_pitch_m * 1e6);
}

}  // namespace

void register_export_iset_command(CLI::App& app) {
  struct Opts {
    std::string exr, out, name, camera;
    std::optional<double> distance, hfov;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("export-iset", "write a spectral radiance EXR as an ISETCam scene (.mat) for sceneGet/oiCompute/sensorCompute");
  cmd->add_option("radiance", o->exr, "spectral radiance EXR (oralfluor render, or any Fichet-Pacanowski-Wilkie EXR)")->required();
  cmd->add_option("-o,--out", o->out, "output .mat file (default: scene.mat, or oi.mat with --camera)");
  cmd->add_option("--camera", o->camera, "write the optical image this camera's lens, filters and optics stage form (ISETCam oi)");
  cmd->add_option("--name", o->name, "scene name (default: the EXR's file stem)");
  cmd->add_option("--distance", o->distance, "scene distance in metres (default: median depth of the render's aov.depth)")
      ->check(finite_positive());
  cmd->add_option("--hfov", o->hfov, "horizontal field of view in degrees (default: from oralfluor.vfov_deg)")->check(finite_range(1e-6, 179.9));
  cmd->add_flag("--json", o->json, "print a JSON summary");
  cmd->callback([o] {
    SpectralImage img = read_spectral_exr(o->exr);
    if (!o->camera.empty()) {
      if (o->distance || o->hfov || !o->name.empty())
        throw InputError("command line", "--camera", "the optical image takes its geometry from the camera: drop --distance, --hfov and --name");
      export_oi(img, *o);
      return;
    }
    if (o->out.empty()) o->out = "scene.mat";
    IsetSceneOptions opt{o->name, o->distance, o->hfov};
    IsetScene s = make_iset_scene(img, opt, o->exr);
    write_iset_scene(o->out, s);
    for (auto& w : s.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    nlohmann::json j = {{"file", o->out},         {"rows", img.height},          {"cols", img.width},
                        {"wave_nm", img.band_nm}, {"hfov_deg", s.hfov_deg},      {"fov_source", s.fov_source},
                        {"distance_m", s.distance_m}, {"distance_source", s.distance_source},
                        {"photon_sum", s.photon_sum}, {"illuminant", s.has_illuminant}, {"warnings", s.warnings}};
    if (o->json) {
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    std::printf("wrote %s: ISETCam scene %dx%d, %d wavelengths %g-%g nm, wAngular %.3f deg (%s), distance %.4g m (%s)%s\n",
                o->out.c_str(), img.height, img.width, img.bands(), img.band_nm.front(), img.band_nm.back(), s.hfov_deg,
                s.fov_source.c_str(), s.distance_m, s.distance_source.c_str(), s.has_illuminant ? ", with the LED illuminant" : "");
  });
}

}  // namespace ofl
