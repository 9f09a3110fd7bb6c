// `oralfluor import-iset file.mat -o out`: brings an ISETCam object into oralfluor. A sensor
// (sensorCreate's struct) becomes a camera file (camera.json, renderer/formats/iset_sensor.h); a
// scene becomes a spectral radiance EXR that `oralfluor camera` can take.
#include <cctype>
#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

#include "renderer/core/files/atomic_file.h"
#include "renderer/camera/description/camera_description.h"
#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/interop/iset_scene.h"
#include "renderer/formats/iset_sensor.h"
#include "renderer/formats/mat_file.h"

namespace ofl {
namespace {

// "sensor" or "scene": the variable of that name, else the type field of the file's structs.
std::string iset_kind(const std::filesystem::path& file) {
  std::string kind;
  for (auto& [name, v] : read_mat_file(file)) {
    if (v.kind != MatValue::Kind::kStruct) continue;
    if (name == "sensor" || name == "scene") return name;
    if (const MatValue* t = v.field("type"); t && t->kind == MatValue::Kind::kText && (t->text == "sensor" || t->text == "scene"))
      kind = t->text;
  }
  if (kind.empty()) throw InputError(file.string(), "variable \"sensor\"", "missing: the file holds no ISETCam sensor or scene struct");
  return kind;
}

std::string lower_extension(const std::string& file) {
  std::string e = std::filesystem::path(file).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// A sensor becomes camera JSON, a scene a spectral EXR: an output name of the other kind is refused
// before anything is written (a scene's EXR bytes in camera.json would load nowhere).
void check_output_kind(const std::string& kind, const std::string& out) {
  if (out.empty()) return;
  const std::string ext = lower_extension(out);
  if (kind == "scene" && ext != ".exr")
    throw InputError(out, "-o", "the input is an ISETCam scene, which becomes a spectral EXR: name the output *.exr "
                                "(a camera file comes from an ISETCam sensor)");
  if (kind == "sensor" && ext != ".json")
    throw InputError(out, "-o", "the input is an ISETCam sensor, which becomes a camera file: name the output *.json "
                                "(a spectral EXR comes from an ISETCam scene)");
}

}  // namespace

void register_import_iset_command(CLI::App& app) {
  struct Opts {
    std::string mat, out;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("import-iset", "convert an ISETCam sensor (.mat) to a camera file, or an ISETCam scene to a spectral EXR");
  cmd->add_option("file", o->mat, "ISETCam .mat holding a sensor or a scene struct")->required();
  cmd->add_option("-o,--out", o->out, "output file (default: camera.json for a sensor, radiance.exr for a scene)");
  cmd->add_flag("--json", o->json, "print a JSON summary");
  cmd->callback([o] {
    std::string kind = iset_kind(o->mat);
    check_output_kind(kind, o->out);
    nlohmann::json summary = {{"input", o->mat}, {"kind", kind}};
    if (kind == "sensor") {
      IsetSensorImport imp = import_iset_sensor(o->mat);
      parse_camera(JsonFile::from(imp.camera, o->mat).root());  // what we write must load
      std::string out = o->out.empty() ? "camera.json" : o->out;
      write_file_atomic(out, imp.camera.dump(2) + "\n");
      summary["output"] = out;
      summary["notes"] = imp.notes;
      for (auto& n : imp.notes) std::fprintf(stderr, "note: %s\n", n.c_str());
    } else {
      SpectralImage img = read_iset_scene(o->mat);
      std::string out = o->out.empty() ? "radiance.exr" : o->out;
      write_spectral_exr(out, img);
      summary["output"] = out;
      summary["size"] = {img.width, img.height};
      summary["wave_nm"] = img.band_nm;
    }
    if (o->json) std::printf("%s\n", summary.dump(2).c_str());
    else std::printf("wrote %s from the ISETCam %s in %s\n", summary["output"].get<std::string>().c_str(), kind.c_str(), o->mat.c_str());
  });
}

}  // namespace ofl
