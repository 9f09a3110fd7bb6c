// The documents of a design point: JSON-pointer edits, variants, and the LED-rig generators,
// checked on the LEDs the scene loader builds from the edited scene (an independent reading of
// what the edit means).
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "renderer/core/errors/error.h"
#include "renderer/scene/scene.h"
#include "renderer/sweep/design/rig_generators.h"
#include "renderer/sweep/design/sweep_design.h"

using namespace ofl;

namespace {
const std::string kScenes = std::string(OFL_SOURCE_DIR) + "/scenes/";

SweepSpec spec_with(nlohmann::json params) {
  nlohmann::json j = {{"scene", "../oraleye_385.json"}, {"camera", "../cameras/oraleye.json"}, {"parameters", params}};
  return parse_sweep_spec(JsonFile::from(j, kScenes + "sweeps/test.json"));
}

// Loads only the lights and camera (tiny image, no render).
Scene load(const PointDocuments& d) {
  SceneOverrides ov;
  ov.width = 8;
  ov.height = 6;
  return load_scene(JsonFile::from(d.scene, d.scene_file.string()), ov);
}

double angle_deg(glm::dvec3 a, glm::dvec3 b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
}
}  // namespace

TEST(SweepGenerators, PointerEditsSetRemoveAndRefuseMissingParents) {
  nlohmann::json doc = {{"a", {{"b", 1}, {"c", 2}}}, {"list", {10, 20}}};
  set_at_pointer(doc, "/a/b", 5, "sweep.json", "/parameters/0");
  set_at_pointer(doc, "/a/new", "x", "sweep.json", "/parameters/0");
  set_at_pointer(doc, "/a/c", nullptr, "sweep.json", "/parameters/0");
  set_at_pointer(doc, "/list/1", 30, "sweep.json", "/parameters/0");
  EXPECT_EQ(doc, (nlohmann::json{{"a", {{"b", 5}, {"new", "x"}}}, {"list", {10, 30}}}));
  try {
    set_at_pointer(doc, "/nope/b", 1, "sweep.json", "/parameters/3/scene");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "sweep.json");
    EXPECT_EQ(e.field(), "/parameters/3/scene");
    EXPECT_NE(std::string(e.what()).find("/nope"), std::string::npos);
  }
  EXPECT_THROW(set_at_pointer(doc, "/list/5", 1, "s", "f"), InputError);
}

TEST(SweepGenerators, LedCountRadiusAndTiltReachTheLoadedLeds) {
  SweepSpec s = spec_with({{{"name", "n"}, {"generator", "led_count"}, {"values", {4}}},
                           {{"name", "r"}, {"generator", "ring_radius"}, {"values", {0.02}}},
                           {{"name", "t"}, {"generator", "led_tilt"}, {"values", {12.5}}}});
  auto d = point_documents(s, make_design(s)[0].values);
  EXPECT_FALSE(d.scene["lights"][0].contains("aim_distance_m"));  // tilt replaces the aim distance
  Scene sc = load(d);
  ASSERT_EQ(sc.lights.size(), 4u);
  glm::dvec3 center(0.012, 0, 0.016), target(-0.075, 0, -0.004);
  glm::dvec3 axis = glm::normalize(target - center);
  for (auto& l : sc.lights) {
    EXPECT_NEAR(glm::length(l.position - center), 0.02, 1e-12);
    EXPECT_NEAR(glm::dot(l.position - center, axis), 0.0, 1e-12);  // on the ring's plane
    EXPECT_NEAR(angle_deg(l.axis, axis), 12.5, 1e-9);
    // Tilted toward the axis: the LED axis leans to the ring centre.
    EXPECT_LT(glm::dot(l.axis, l.position - center), 0.0);
  }
}

TEST(SweepGenerators, RigDistanceMovesCameraAndRingTogetherKeepingDirections) {
  SweepSpec base = spec_with({{{"name", "n"}, {"generator", "led_count"}, {"values", {6}}}});
  Scene s0 = load(point_documents(base, make_design(base)[0].values));
  SweepSpec s = spec_with({{{"name", "d"}, {"generator", "rig_distance"}, {"values", {0.05}}}});
  PointDocuments d = point_documents(s, make_design(s)[0].values);
  Scene s1 = load(d);
  glm::dvec3 look(-0.075, 0, -0.004);
  EXPECT_NEAR(glm::length(look - s1.camera.position), 0.05, 1e-12);
  glm::dvec3 delta = s1.camera.position - s0.camera.position;
  // Along the camera -> look_at line, toward the tongue.
  EXPECT_NEAR(angle_deg(delta, look - s0.camera.position), 0.0, 1e-6);
  EXPECT_NEAR(glm::length(delta), glm::length(look - s0.camera.position) - 0.05, 1e-12);
  ASSERT_EQ(s1.lights.size(), s0.lights.size());
  for (size_t i = 0; i < s0.lights.size(); ++i) {
    glm::dvec3 moved = s1.lights[i].position - s0.lights[i].position;
    EXPECT_NEAR(glm::length(moved - delta), 0.0, 1e-12);
    EXPECT_NEAR(angle_deg(s1.lights[i].axis, s0.lights[i].axis), 0.0, 1e-6);
  }
  EXPECT_EQ(d.scene["camera"]["look_at"], (nlohmann::json{-0.075, 0, -0.004}));
}

TEST(SweepGenerators, FiltersHalfAngleSpectrumAndVariants) {
  SweepSpec s = spec_with({{{"name", "half"}, {"generator", "led_half_angle"}, {"values", {20}}},
                           {{"name", "sp"}, {"generator", "led_filter_edge"}, {"values", {440}}},
                           {{"name", "lp"}, {"generator", "camera_filter_edge"}, {"values", {490}}},
                           {{"name", "fwhm"}, {"generator", "led_fwhm"}, {"peak_nm", 390}, {"values", {25}}},
                           {{"name", "v"}, {"variants", {{{"label", "plain"}},
                                                         {{"label", "glass"}, {"camera", {{"/filters/0/interference", false}}},
                                                          {"scene", {{"/materials/teeth", {{"type", "lambertian"}, {"reflectance", 0}}}}}}}}}});
  auto design = make_design(s);
  ASSERT_EQ(design.size(), 2u);
  PointDocuments d = point_documents(s, design[1].values);
  const auto& l = d.scene["lights"][0];
  EXPECT_EQ(l["profile"], (nlohmann::json{{"half_angle_deg", 20}}));
  EXPECT_EQ(l["filter"]["edge_nm"], 440);
  EXPECT_EQ(l["spd"], (nlohmann::json{{"type", "gaussian"}, {"peak_nm", 390.0}, {"fwhm_nm", 25}}));
  EXPECT_EQ(d.camera["filters"][0]["edge_nm"], 490);
  EXPECT_EQ(d.camera["filters"][0]["interference"], false);
  EXPECT_EQ(d.scene["materials"]["teeth"]["type"], "lambertian");
  PointDocuments plain = point_documents(s, design[0].values);
  EXPECT_EQ(plain.camera["filters"][0]["interference"], true);
  // led_fwhm without peak_nm on a measured LED cannot know the peak: an error naming the parameter.
  SweepSpec bad = spec_with({{{"name", "fwhm"}, {"generator", "led_fwhm"}, {"values", {25}}}});
  try {
    point_documents(bad, make_design(bad)[0].values);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/parameters/0/peak_nm");
  }
}
