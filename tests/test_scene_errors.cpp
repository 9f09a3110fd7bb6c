// Bad scene input gives one clear line naming the file and the JSON field, and exit code 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "renderer/core/errors/error.h"
#include "renderer/scene/scene.h"
#include "tests/cli_runner.h"

using namespace ofl;
using nlohmann::json;

namespace {
std::filesystem::path tmpdir() {
  auto d = std::filesystem::temp_directory_path() / "ofl_scene_errors";
  std::filesystem::create_directories(d);
  return d;
}

json good_scene() {
  return json::parse(R"({
    "format": "oralfluor-scene", "version": 1,
    "integrator": {"spp": 1, "max_depth": 2},
    "camera": {"position": [0, 0, 0.3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 20, "resolution": [8, 8]},
    "materials": {"patch": {"type": "lambertian", "reflectance": 0.5}},
    "geometry": [{"type": "quad", "center": [0, 0, 0], "u": [0.1, 0, 0], "v": [0, 0.1, 0], "material": "patch"}],
    "lights": [
      {"spd": 1.0, "radiant_intensity_W_sr": 1, "position": [0, 0, 0.1], "axis": [0, 0, -1]},
      {"spd": 1.0, "radiant_intensity_W_sr": 1, "position": [0, 0.01, 0.1], "axis": [0, 0, -1]},
      {"spd": 1.0, "radiant_intensity_W_sr": 1, "position": [0, 0.02, 0.1], "axis": [0, 0, -1]}
    ]})");
}

std::string write(const std::string& name, const std::string& text) {
  auto p = tmpdir() / name;
  std::ofstream(p) << text;
  return p.string();
}

// Loads a scene and returns "<field>|<what>" of the InputError (empty when none).
std::string error_of(const json& j, const std::string& name) {
  auto f = write(name, j.dump(2));
  try {
    load_scene(f);
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), f);
    return e.field() + "|" + e.what();
  }
  return "";
}
}  // namespace

TEST(SceneErrors, GoodSceneLoads) { EXPECT_EQ(error_of(good_scene(), "good.json"), ""); }

TEST(SceneErrors, NamesTheJsonPointer) {
  auto j = good_scene();
  j["lights"][2]["axis"] = {0, 0};
  EXPECT_EQ(error_of(j, "axis.json").substr(0, 16), "/lights/2/axis|e");
  j = good_scene();
  j["lights"][1].erase("axis");
  EXPECT_EQ(error_of(j, "noaxis.json").substr(0, 10), "/lights/1|");
  j = good_scene();
  j["camera"]["resolution"] = {8, -1};
  EXPECT_EQ(error_of(j, "res.json").substr(0, 21), "/camera/resolution/1|");
  j = good_scene();
  j["materials"]["patch"]["reflectance"] = 1.5;
  EXPECT_EQ(error_of(j, "refl.json").substr(0, 29), "/materials/patch/reflectance|");
  j = good_scene();
  j["geometry"][0]["material"] = "nope";
  EXPECT_NE(error_of(j, "mat.json").find("/geometry/0/material|no material named \"nope\""), std::string::npos);
  j = good_scene();
  j["lights"][0]["radious_m"] = 0.01;  // typo
  EXPECT_NE(error_of(j, "typo.json").find("/lights/0/radious_m|unknown field"), std::string::npos);
  j = good_scene();
  j["version"] = 7;
  EXPECT_NE(error_of(j, "ver.json").find("/version|unsupported"), std::string::npos);
}

TEST(SceneErrors, SpectrumFileProblemsNameFileAndLine) {
  auto csv = write("bad_spd.csv", "wavelength_nm,v\n400,1\n410,NaN\n420,1\n");
  auto j = good_scene();
  j["lights"][0]["spd"] = csv;
  try {
    load_scene(write("spd.json", j.dump()));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), csv);
    EXPECT_EQ(e.field(), "line 3 column \"v\"");
  }
}

TEST(SceneErrors, CliExitCodeTwoAndOneLine) {
  auto f = write("malformed.json", "{\n  \"format\": \"oralfluor-scene\",\n  \"version\": 1,\n  \"camera\": {,\n}");
  auto r = test::run_cli("render " + f + " -o " + (tmpdir() / "out").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(r.output, "error: " + f + ": line 4 column 14: malformed JSON: syntax error while parsing object key - unexpected ','; expected string literal\n");

  r = test::run_cli("render " + (tmpdir() / "missing.json").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("missing.json: cannot open file"), std::string::npos) << r.output;

  auto j = good_scene();
  j["geometry"] = {{{"type", "gltf"}, {"file", write("broken.glb", "glTF this is not")}}};
  r = test::run_cli("render " + write("broken.json", j.dump()) + " -o " + (tmpdir() / "out").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("broken.glb: broken glTF"), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

TEST(SceneErrors, ABrokenReferencedFileNamesItselfAndTheEntryThatNamedIt) {
  // A NaN inside a reflectance CSV: the CSV and its line, and the scene field that referred to it.
  auto csv = write("nan_reflectance.csv", "wavelength_nm,value\n400,0.5\n500,nan\n600,0.5\n");
  auto j = good_scene();
  j["materials"]["patch"]["reflectance"] = csv;
  auto scene = write("refers_to_nan.json", j.dump());
  try {
    load_scene(scene);
    FAIL() << "NaN reflectance accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), csv);
    EXPECT_EQ(e.field(), "line 3 column \"value\"");
    EXPECT_NE(std::string(e.what()).find("(named by " + scene + " /materials/patch/reflectance)"), std::string::npos)
        << e.what();
  }
  // A broken glTF: the .glb and the geometry entry, on one line, exit code 2.
  j = good_scene();
  auto glb = write("broken_named.glb", "glTF this is not");
  j["geometry"] = {{{"type", "gltf"}, {"file", glb}}};
  scene = write("refers_to_broken.json", j.dump());
  auto r = test::run_cli("render " + scene + " -o " + (tmpdir() / "out").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(r.output.rfind("error: " + glb + ": ", 0), 0u) << r.output;
  EXPECT_NE(r.output.find("(named by " + scene + " /geometry/0/file)"), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}
