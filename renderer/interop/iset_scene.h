// A spectral radiance image as an ISETCam scene structure (the variable `scene` of a .mat file, as
// ISETCam's sceneSave writes it), and back. The fields are the ones ISETCam's sceneGet, oiCompute
// and sensorCompute read:
//   scene.type          'scene'
//   scene.name          text
//   scene.spectrum.wave wavelengths (nm, column vector): the EXR's band centres
//   scene.data.photons  single, rows x cols x nWave, photons s^-1 sr^-1 m^-2 nm^-1
//                       (the EXR's W sr^-1 m^-2 nm^-1 times lambda / (h c))
//   scene.data.bitDepth 32 (single precision photons)
//   scene.data.luminance rows x cols, cd/m^2 (683 lm/W x CIE 1931 y-bar, over the bands)
//   scene.distance      metres from the camera to the scene (median depth of the pixels that see
//                       geometry, from the render's aov.depth, unless given)
//   scene.wAngular      horizontal field of view in degrees (from oralfluor.vfov_deg and the aspect)
//   scene.magnification 1
//   scene.illuminant    when the EXR records its LEDs (oralfluor.excitation_spd): type
//                       'illuminant', name, spectrum.wave, data.photons (column, single): the
//                       radiance of a perfect white Lambertian reflector at the median LED
//                       irradiance of the pixels that see geometry (aov.irradiance), so that
//                       scene photons ./ illuminant photons reads as an apparent reflectance there
//   scene.metadata      oralfluor's header strings (source, seed, spp, ...) and, when rendered,
//                       fluorescencePhotons (the fluorescent part, same layout as data.photons),
//                       aov.<name> (each AOV plane, rows x cols single) and exrAttributes (every
//                       header string under its own name, as JSON text): ISETCam ignores them,
//                       read_iset_scene restores them, so an export imports back as the EXR it was
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "renderer/image/spectral_image.h"
#include "renderer/interop/mat_file.h"

namespace ofl {

struct IsetSceneOptions {
  std::string name;                   // default: the source file's stem
  std::optional<double> distance_m;   // default: median depth from aov.depth
  std::optional<double> hfov_deg;     // default: from oralfluor.vfov_deg
};

struct IsetScene {
  MatValue scene;                     // the struct written as variable "scene"
  double distance_m = 0, hfov_deg = 0;
  std::string distance_source, fov_source;
  double photon_sum = 0;              // sum of data.photons (as stored, single precision)
  bool has_illuminant = false;
  std::vector<std::string> warnings;  // light or data the ISETCam scene cannot carry
};

// InputError (file = `source`) when the distance or field of view is neither recorded nor given.
IsetScene make_iset_scene(const SpectralImage& img, const IsetSceneOptions& opt, const std::string& source);
void write_iset_scene(const std::filesystem::path& file, const IsetScene& s);

// An ISETCam scene .mat (variable `scene`, or the only struct of type 'scene') as a spectral
// radiance image (W sr^-1 m^-2 nm^-1), with oralfluor.vfov_deg from wAngular and the distance in
// oralfluor.iset_distance_m; the fluorescence layer, AOV planes and header strings when the
// metadata holds them (an exported scene). Errors name the file and the field (e.g. "scene.data.photons").
SpectralImage read_iset_scene(const std::filesystem::path& file);

}  // namespace ofl
