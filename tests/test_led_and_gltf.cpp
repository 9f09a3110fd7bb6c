// LED angular profiles and flux, and glTF loading with node transforms.
#include <gtest/gtest.h>

#include <tiny_gltf.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include <glm/gtc/matrix_transform.hpp>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/scene/led_light.h"
#include "renderer/mesh/files/gltf_reader.h"
#include "renderer/mesh/geometry/mesh_measure.h"
#include "renderer/spectral/spectra/units.h"

using namespace ofl;

TEST(LedProfile, HalfAngleGivesHalfIntensity) {
  for (double half : {10.0, 30.0, 60.0}) {
    LedProfile p;
    p.cos_power = LedProfile::cos_power_from_half_angle(half);
    EXPECT_NEAR(p.eval(std::cos(half * kPi / 180)), 0.5, 1e-12);
  }
  LedProfile lam;
  lam.cos_power = 1;
  EXPECT_NEAR(LedProfile::cos_power_from_half_angle(60), 1.0, 1e-12);  // Lambertian: 60 deg
  EXPECT_NEAR(lam.solid_angle_integral(), kPi, 1e-12);
}

TEST(LedProfile, TableOfCosPowerIntegratesLikeTheFormula) {
  // A finely tabulated cos^3 profile has the solid-angle integral 2 pi / 4.
  nlohmann::json rows = nlohmann::json::array();
  for (int a = 0; a <= 90; ++a) rows.push_back({a, std::pow(std::cos(a * kPi / 180), 3)});
  nlohmann::json led = {{"spd", 1.0}, {"flux_W", 2.0}, {"profile", {{"table", rows}}}, {"position", {0, 0, 0}}, {"axis", {0, 0, 1}}};
  JsonFile f = JsonFile::from(led, "led");
  WavelengthGrid g{400, 700, 10};
  LedLight l = parse_led(f.root(), g);
  EXPECT_NEAR(l.profile.solid_angle_integral(), 2 * kPi / 4, 2e-3);
  // Flux -> intensity: I0 = flux / integral P d omega.
  EXPECT_NEAR(l.intensity_W_sr, 2.0 / (2 * kPi / 4), 5e-3);
  EXPECT_NEAR(l.power_W, 2.0, 1e-9);
}

TEST(LedProfile, IesFileGivesTheCandelaShape) {
  // A Lambertian LED written as LM-63: I(theta) = 100 cd cos(theta), two horizontal planes.
  auto f = std::filesystem::temp_directory_path() / "ofl_lambert.ies";
  {
    std::ofstream o(f);
    o << "IESNA:LM-63-2002\n[TEST] lambertian\nTILT=NONE\n1 -1 1 19 2 1 2 0 0 0\n1 1 1\n";
    for (int a = 0; a <= 90; a += 5) o << a << " ";
    o << "\n0 90\n";
    for (int h = 0; h < 2; ++h) {
      for (int a = 0; a <= 90; a += 5) o << 100 * std::cos(a * kPi / 180) << " ";
      o << "\n";
    }
  }
  nlohmann::json led = {{"spd", 1.0}, {"flux_W", 1.0}, {"profile", {{"ies_file", f.string()}}}, {"position", {0, 0, 0}}, {"axis", {0, 0, 1}}};
  LedLight l = parse_led(JsonFile::from(led, "led").root(), WavelengthGrid{400, 700, 10});
  EXPECT_NEAR(l.profile.eval(std::cos(60 * kPi / 180)), 0.5, 2e-3);
  EXPECT_NEAR(l.profile.solid_angle_integral(), kPi, 2e-3);  // Lambertian: pi sr
  std::ofstream(f) << "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 19 2 1 2 0 0 0\n1 1 1\n0 5 x\n";
  EXPECT_THROW(parse_led(JsonFile::from(led, "led").root(), WavelengthGrid{400, 700, 10}), InputError);
}

TEST(LedLight, ShortPassFilterRemovesPower) {
  nlohmann::json led = {{"spd", {{"type", "gaussian"}, {"peak_nm", 450}, {"fwhm_nm", 20}}}, {"radiant_intensity_W_sr", 1.0},
                        {"filter", {{"type", "shortpass"}, {"edge_nm", 450}, {"width_nm", 0.1}, {"od", 6}, {"peak", 1.0}}},
                        {"position", {0, 0, 0}}, {"target", {0, 0, -1}}};
  JsonFile f = JsonFile::from(led, "led");
  LedLight l = parse_led(f.root(), WavelengthGrid{350, 830, 1});
  EXPECT_NEAR(l.intensity_W_sr, 0.5, 0.02);  // half of a symmetric line passes a sharp edge at its peak
}

TEST(LedLight, FilterTakesEverySpectrumForm) {
  // A transmittance CSV named by a string (as scene-format.md's "Spectra" allows), a constant and
  // points: a flat 0.3 from a file, times 0.5, times a ramp that is 1 at the line's 450 nm peak.
  auto csv = std::filesystem::temp_directory_path() / "ofl_led_filter.csv";
  std::ofstream(csv) << "wavelength_nm,t\n300,0.3\n900,0.3\n";
  auto led_with = [&](nlohmann::json filter) {
    nlohmann::json led = {{"spd", {{"type", "gaussian"}, {"peak_nm", 450}, {"fwhm_nm", 4}}}, {"radiant_intensity_W_sr", 1.0},
                          {"filters", filter}, {"position", {0, 0, 0}}, {"target", {0, 0, -1}}};
    return parse_led(JsonFile::from(led, "led").root(), WavelengthGrid{350, 830, 1});
  };
  EXPECT_NEAR(led_with({csv.string()}).intensity_W_sr, 0.3, 1e-9);
  EXPECT_NEAR(led_with({csv.string(), 0.5}).intensity_W_sr, 0.15, 1e-9);
  nlohmann::json ramp = {{"type", "points"}, {"points", {{440, 0.9}, {460, 1.1}}}};  // 1 at 450, antisymmetric: mean 1
  EXPECT_THROW(led_with({ramp}), InputError);  // above 1: not a transmittance
  ramp["points"] = {{440, 0.8}, {460, 1.0}};   // 0.9 at 450, linear: the symmetric line sees 0.9
  EXPECT_NEAR(led_with({ramp}).intensity_W_sr, 0.9, 1e-3);
}

namespace {
// A one-triangle glTF whose node has translation, rotation and scale.
std::filesystem::path write_triangle_gltf() {
  tinygltf::Model m;
  std::vector<float> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  tinygltf::Buffer buf;
  buf.data.resize(pos.size() * 4);
  std::memcpy(buf.data.data(), pos.data(), buf.data.size());
  m.buffers.push_back(buf);
  tinygltf::BufferView bv;
  bv.buffer = 0;
  bv.byteLength = buf.data.size();
  m.bufferViews.push_back(bv);
  tinygltf::Accessor acc;
  acc.bufferView = 0;
  acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  acc.count = 3;
  acc.type = TINYGLTF_TYPE_VEC3;
  acc.minValues = {0, 0, 0};
  acc.maxValues = {1, 1, 0};
  m.accessors.push_back(acc);
  tinygltf::Material mat;
  mat.name = "tongue";
  m.materials.push_back(mat);
  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = 0;
  prim.material = 0;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh mesh;
  mesh.primitives.push_back(prim);
  m.meshes.push_back(mesh);
  tinygltf::Node parent, child;
  parent.translation = {1, 2, 3};
  parent.children = {1};
  child.mesh = 0;
  child.scale = {2, 2, 2};
  child.rotation = {0, 0, std::sin(kPi / 4), std::cos(kPi / 4)};  // 90 deg about z
  m.nodes = {parent, child};
  tinygltf::Scene s;
  s.nodes = {0};
  m.scenes.push_back(s);
  m.defaultScene = 0;
  auto file = std::filesystem::temp_directory_path() / "ofl_triangle.glb";
  tinygltf::TinyGLTF w;
  w.WriteGltfSceneToFile(&m, file.string(), true, true, false, true);
  return file;
}
}  // namespace

TEST(Gltf, NodeTransformsAreApplied) {
  auto file = write_triangle_gltf();
  auto meshes = read_gltf(file).meshes;
  ASSERT_EQ(meshes.size(), 1u);
  const auto& m = meshes[0];
  EXPECT_EQ(m.material, "tongue");
  // (1,0,0) -> scale 2 -> rotate 90 about z -> (0,2,0) -> translate -> (1,4,3).
  EXPECT_NEAR(m.positions[1].x, 1.0, 1e-6);
  EXPECT_NEAR(m.positions[1].y, 4.0, 1e-6);
  EXPECT_NEAR(m.positions[1].z, 3.0, 1e-6);
  EXPECT_NEAR(surface_area(m), 0.5 * 4, 1e-6);
  // A scene-file transform on top scales the area by s^2.
  auto scaled = read_gltf(file, glm::scale(glm::dmat4(1.0), glm::dvec3(0.01))).meshes;
  EXPECT_NEAR(surface_area(scaled[0]), 2e-4, 1e-10);
}

TEST(Gltf, BenchmarkMeshHasTheStatedTriangleCount) {
  auto meshes = read_gltf(std::filesystem::path(OFL_SOURCE_DIR) / "benchmarks/scenes/tongue_mouth.glb").meshes;
  size_t tris = 0;
  for (auto& m : meshes) tris += m.triangle_count();
  EXPECT_EQ(tris, 197948u);
}

TEST(Gltf, BrokenFileIsAnInputError) {
  auto f = std::filesystem::temp_directory_path() / "ofl_broken.gltf";
  std::ofstream(f) << "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 5}}]}]}";
  try {
    read_gltf(f);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), f.string());
  }
}
