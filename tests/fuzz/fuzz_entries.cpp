#include "tests/fuzz/fuzz_entries.h"
#include "tests/fuzz/diagnose_selection.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <filesystem>
#include <fstream>

#include "renderer/camera/description/camera_description.h"
#include "renderer/core/files/csv.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/diagnose/diagnose_model.h"
#include "renderer/diagnose/problem/measurement_set.h"
#include "renderer/image/image_file.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/interop/iset_scene.h"
#include "renderer/formats/iset_sensor.h"
#include "renderer/formats/mat_file.h"
#include "renderer/mesh/files/gltf_reader.h"
#include "renderer/mesh/files/obj_reader.h"
#include "renderer/scene/ies_profile.h"
#include "renderer/scene/scene.h"
#include "renderer/spectral/chromophores/eem.h"
#include "renderer/spectral/spectra/spectrum.h"
#include "renderer/sweep/design/sweep_spec.h"

namespace ofl::fuzz {
namespace {

namespace fs = std::filesystem;

// This process's scratch folder: a shadow of the source tree in which `sub` (e.g. "scenes/sweeps")
// is a real folder and everything else is a symbolic link to the source, so the relative paths of
// an input placed there (a scene's "../assets/meshes/mouth.glb") reach the shipped files and the
// parsers get past the first file reference.
fs::path shadow_folder(const std::string& sub) {
  static const fs::path root = [] {
    fs::path d = fs::temp_directory_path() / ("ofl_fuzz_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
  }();
  const fs::path src = OFL_SOURCE_DIR;
  fs::path real = root, rel;
  std::error_code ec;
  std::vector<std::string> parts;
  for (const auto& c : fs::path(sub)) parts.push_back(c.string());
  for (size_t i = 0;; ++i) {
    // Link every child of the source folder except the next real component.
    if (!fs::exists(real / ".shadowed")) {
      for (const auto& e : fs::directory_iterator(src / rel, ec)) {
        std::string n = e.path().filename().string();
        if ((i < parts.size() && n == parts[i]) || n == "build" || n == ".git") continue;
        fs::create_symlink(e.path(), real / n, ec);
      }
      std::ofstream(real / ".shadowed");
    }
    if (i == parts.size()) return real;
    rel /= parts[i];
    real /= parts[i];
    // Linked by an earlier, shallower shadow: replace the link by a real folder (never write
    // through a link into the source tree).
    if (fs::is_symlink(real)) fs::remove(real);
    fs::create_directories(real);
  }
}

// The input as a file named input<ext> in the shadow folder `sub`.
fs::path as_file(const uint8_t* data, size_t size, const char* ext, const std::string& sub = "") {
  fs::path p = shadow_folder(sub) / (std::string("input") + ext);
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return p;
}

std::string as_text(const uint8_t* data, size_t size) { return std::string(reinterpret_cast<const char*>(data), size); }

// Round trips through ISETCam files: what oralfluor writes must read back as what it wrote. A
// difference is a finding (std::logic_error), not an input error.
[[noreturn]] void round_trip_failed(const std::string& what) { throw std::logic_error("ISETCam round trip: " + what); }

// Radiance read back from an exported scene against the image exported: the same grid and bands,
// every value within single precision (the scene stores photons as single).
void compare_radiance(const SpectralImage& a, const SpectralImage& b) {
  if (a.width != b.width || a.height != b.height) round_trip_failed("size changed");
  if (a.band_nm.size() != b.band_nm.size()) round_trip_failed("band count changed");
  for (size_t i = 0; i < a.band_nm.size(); ++i)
    if (std::abs(a.band_nm[i] - b.band_nm[i]) > 1e-9 * std::abs(a.band_nm[i])) round_trip_failed("band centre changed");
  for (size_t i = 0; i < a.data.size(); ++i) {
    const double x = a.data[i], y = b.data[i];
    if (!(std::abs(x - y) <= 4e-7 * std::max(std::abs(x), std::abs(y)) + 1e-37))
      round_trip_failed("radiance value " + std::to_string(i) + " was " + std::to_string(x) + ", reads back " + std::to_string(y));
  }
}

// An exported scene .mat read back (import-iset's reader).
SpectralImage export_and_read_back(const SpectralImage& img, const IsetSceneOptions& opt) {
  IsetScene scene = make_iset_scene(img, opt, "input.exr");
  const fs::path mat = shadow_folder("") / "round_trip.mat";
  write_iset_scene(mat, scene);
  return read_iset_scene(mat);
}

// export-iset: a spectral EXR (any the reader accepts) to an ISETCam scene and back.
void iset_export(const uint8_t* d, size_t n) {
  SpectralImage img = read_spectral_exr(as_file(d, n, ".exr"));
  IsetSceneOptions opt;
  opt.distance_m = 0.3;  // an EXR without aov.depth or a field of view still exports with these
  opt.hfov_deg = 20;
  compare_radiance(img, export_and_read_back(img, opt));
}

// import-iset: an ISETCam .mat (scene or sensor). A scene that imports must export and import
// again to the same radiance; a sensor that imports must give a camera file that loads.
void iset_import(const uint8_t* d, size_t n) {
  const fs::path file = as_file(d, n, ".mat");
  bool sensor = false;
  for (auto& [name, v] : read_mat_file(file))
    if (v.kind == MatValue::Kind::kStruct) sensor = sensor || name == "sensor";
  if (sensor) {
    IsetSensorImport imp = import_iset_sensor(file);
    parse_camera(JsonFile::from(imp.camera, file.string()).root());
    return;
  }
  SpectralImage img = read_iset_scene(file);
  IsetSceneOptions opt;
  opt.distance_m = 0.3;
  opt.hfov_deg = 20;
  compare_radiance(img, export_and_read_back(img, opt));
}

}  // namespace

const std::vector<Entry>& entries() {
  static const std::vector<Entry> e = {
      {"scene_json", ".json", [](const uint8_t* d, size_t n) { load_scene(as_file(d, n, ".json", "scenes")); },
       {"scenes/minimal.json", "scenes/lesion_385.json", "scenes/oraleye_385.json", "tests/data/bad_inputs/gltf_ok.json"}},
      {"camera_json", ".json", [](const uint8_t* d, size_t n) { load_camera(as_file(d, n, ".json", "scenes/cameras")); },
       {"scenes/cameras/oraleye.json", "scenes/cameras/plain_rgb.json"}},
      {"sweep_json", ".json", [](const uint8_t* d, size_t n) { load_sweep_spec(as_file(d, n, ".json", "scenes/sweeps")); },
       {"scenes/sweeps/tiny.json", "scenes/sweeps/led_ring.json"}},
      {"spectrum_csv", ".csv", [](const uint8_t* d, size_t n) { read_spectrum_csv(as_file(d, n, ".csv")); },
       {"assets/sensors/MT9V024_RGB.csv", "assets/measurements/camera_example/radiance.csv"}},
      {"eem_csv", ".csv", [](const uint8_t* d, size_t n) { read_eem_csv(as_file(d, n, ".csv")); },
       {"tests/data/bad_inputs/eem_albedo_above_one.csv", "assets/fluorophores/FAD_Webfluor_EEM.csv"}},
      {"mat", ".mat", [](const uint8_t* d, size_t n) { read_mat_file(as_file(d, n, ".mat")); }, {"tests/fuzz/seeds/small_scene.mat"}},
      {"diagnose_model", ".json", [](const uint8_t* d, size_t n) { load_diagnose_model(as_file(d, n, ".json", "scenes/diagnose")); },
       {"scenes/diagnose/camera_example.json", "scenes/diagnose/oe_tongue_lip.json"}},
      {"diagnose_index", ".csv",
       [](const uint8_t* d, size_t n) {
         fs::path p = as_file(d, n, ".csv", "assets/measurements/camera_example");
         try {
           read_spectra_index(p, "csv", {});
         } catch (const InputError&) {
         }
         read_camera_patches(p, {});
       },
       {"assets/measurements/oe_tongue_lip/index.csv", "assets/measurements/camera_example/patches.csv"}},
      {"gltf", ".gltf", [](const uint8_t* d, size_t n) { read_gltf(as_file(d, n, ".gltf", "tests/data/bad_inputs")); },
       {"tests/data/bad_inputs/gltf_ok.gltf", "tests/data/bad_inputs/gltf_offset_wrap.gltf", "tests/data/bad_inputs/gltf_huge_count.gltf"}},
      {"glb", ".glb", [](const uint8_t* d, size_t n) { read_gltf(as_file(d, n, ".glb")); }, {"tests/fuzz/seeds/quad.glb", "assets/meshes/teeth.glb"}},
      {"obj", ".obj", [](const uint8_t* d, size_t n) { parse_obj(as_text(d, n), "input.obj"); }, {"tests/fuzz/seeds/quad.obj"}},
      {"ies", ".ies", [](const uint8_t* d, size_t n) { read_ies_profile(as_file(d, n, ".ies")); },
       {"tests/fuzz/seeds/lambert.ies", "tests/data/bad_inputs/ies_negative_candela.ies", "tests/data/bad_inputs/ies_zero_axis.ies", "tests/data/bad_inputs/ies_huge_count.ies"}},
      {"spectral_exr", ".exr", [](const uint8_t* d, size_t n) { read_spectral_exr(as_file(d, n, ".exr")); },
       {"tests/fuzz/seeds/small_radiance.exr", "tests/data/bad_inputs/exr_huge_string.exr"}},
      {"image_png", ".png", [](const uint8_t* d, size_t n) { read_image_file(as_file(d, n, ".png")); },
       {"tests/data/bad_inputs/png_huge_header.png", "assets/textures/tongue_lesion.png"}},
      {"diagnose_selection", ".bin", [](const uint8_t* d, size_t n) { run_diagnose_selection(d, n); },
       {"tests/fuzz/seeds/diagnose_selection_spectra.bin", "tests/fuzz/seeds/diagnose_selection_edge.bin",
        "tests/fuzz/seeds/diagnose_selection_set_aside.bin", "tests/fuzz/seeds/diagnose_selection_camera.bin"}},
      {"iset_export", ".exr", iset_export, {"tests/fuzz/seeds/small_radiance.exr"}},
      {"iset_import", ".mat", iset_import, {"tests/fuzz/seeds/small_scene.mat", "tests/fuzz/seeds/small_sensor.mat"}},
  };
  return e;
}

const Entry* find_entry(const std::string& name) {
  for (const auto& e : entries())
    if (name == e.name) return &e;
  return nullptr;
}

int run_entry(const Entry& e, const uint8_t* data, size_t size) {
  try {
    e.run(data, size);
  } catch (const InputError& x) {
    // the documented answer to a bad input (OFL_FUZZ_VERBOSE=1 shows it)
    static const bool verbose = std::getenv("OFL_FUZZ_VERBOSE") != nullptr;
    if (verbose) std::fprintf(stderr, "fuzz_%s: %s\n", e.name, x.describe().c_str());
  }
  return 0;
}

void init_fuzz_environment() {
  ::setenv("OFL_MEMORY_LIMIT_MIB", "1024", 0);
  ::setenv("OFL_NO_PROGRESS", "1", 0);
}

}  // namespace ofl::fuzz
