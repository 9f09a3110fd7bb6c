#include "tests/fuzz/fuzz_entries.h"
#include "tests/fuzz/diagnose_selection.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "renderer/camera/camera_description.h"
#include "renderer/core/csv.h"
#include "renderer/core/error.h"
#include "renderer/core/json_node.h"
#include "renderer/diagnose/diagnose_model.h"
#include "renderer/diagnose/measurement_set.h"
#include "renderer/image/image_file.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/interop/mat_file.h"
#include "renderer/mesh/gltf_reader.h"
#include "renderer/mesh/obj_reader.h"
#include "renderer/scene/ies_profile.h"
#include "renderer/scene/scene.h"
#include "renderer/spectral/eem.h"
#include "renderer/spectral/spectrum.h"
#include "renderer/sweep/sweep_spec.h"

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
