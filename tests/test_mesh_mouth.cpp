// The procedural mouth: watertight and outward-facing where promised, and its measured
// geometry equals its parameters (lip opening, cavity volume, tongue volume and tip).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "renderer/core/errors/error.h"
#include "renderer/mesh/files/gltf_reader.h"
#include "renderer/mesh/files/gltf_writer.h"
#include "renderer/mesh/geometry/mesh_measure.h"
#include "renderer/mesh/mouth/mouth_generator.h"
#include "renderer/mesh/mouth/procedural_tongue.h"

using namespace ofl;

namespace {

std::vector<TriangleMesh> parts_except(const Mouth& m, const std::string& material) {
  std::vector<TriangleMesh> out;
  for (auto& p : m.parts)
    if (p.material != material) out.push_back(p);
  return out;
}

const TriangleMesh& part(const Mouth& m, const std::string& name) {
  for (auto& p : m.parts)
    if (p.name == name) return p;
  throw std::runtime_error("no part " + name);
}

// Vertical gap between the lips on the midline: lowest upper-lip point minus highest lower-lip
// point among vertices with |y| below a tolerance.
double measured_opening(const Mouth& m) {
  double top = 1e9, bottom = -1e9;
  for (auto& v : part(m, "upper_lip").positions)
    if (std::abs(v.y) < 1e-4) top = std::min(top, static_cast<double>(v.z));
  for (auto& v : part(m, "lower_lip").positions)
    if (std::abs(v.y) < 1e-4) bottom = std::max(bottom, static_cast<double>(v.z));
  return top - bottom;
}

double gamma_ratio(double n) { return std::tgamma(1 + 1 / n) * std::tgamma(1 + 1 / n) / std::tgamma(1 + 2 / n); }

}  // namespace

TEST(MeshMouth, WatertightOutwardAndUvsInUnitSquare) {
  MouthParams p;
  p.segments = 64;
  Mouth m = make_mouth(p);
  std::vector<TriangleMesh> shell = parts_except(m, "tongue");
  EXPECT_EQ(shell.size(), 7u);
  EdgeStats e = edge_stats(shell);
  EXPECT_TRUE(e.watertight()) << "boundary " << e.boundary << " non-manifold " << e.non_manifold;
  EXPECT_TRUE(e.consistently_oriented()) << e.misoriented;
  EXPECT_EQ(e.degenerate_triangles, 0u);
  // Normals out of the tissue: the solid has positive volume, and it is the head block minus
  // the cavity, so less than the block's bounding box.
  double v = enclosed_volume(shell);
  EXPECT_GT(v, 0);
  EXPECT_LT(v, p.face_width_m * p.face_height_m * p.head_depth_m);
  for (auto& part : m.parts) {
    ASSERT_EQ(part.uvs.size(), part.positions.size()) << part.name;
    ASSERT_EQ(part.normals.size(), part.positions.size()) << part.name;
    EXPECT_TRUE(uv_range(part).within_unit_square()) << part.name;
    for (auto& n : part.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f) << part.name;
  }
  // The materials the scenes bind.
  std::set<std::string> materials;
  for (auto& part : m.parts) materials.insert(part.material);
  EXPECT_EQ(materials, (std::set<std::string>{"skin", "lips", "cheek", "palate", "floor", "tongue"}));
}

TEST(MeshMouth, LipOpeningEqualsTheParameter) {
  for (double opening : {0.02, 0.035, 0.05}) {
    MouthParams p;
    p.opening_m = opening;
    p.segments = 64;
    p.tongue = false;
    Mouth m = make_mouth(p);
    EXPECT_NEAR(measured_opening(m), opening, 0.02 * opening) << opening;
    // Width: the inner lip edges at the corners are the lip points nearest the axis on z = 0.
    double half = 1e9;
    for (auto& part : m.parts)
      if (part.material == "lips")
        for (auto& v : part.positions)
          if (std::abs(v.z) < 1e-6) half = std::min(half, std::abs(static_cast<double>(v.y)));
    EXPECT_NEAR(2 * half, p.opening_width_m, 0.02 * p.opening_width_m);
  }
}

TEST(MeshMouth, CavityVolumeEqualsClosedForm) {
  // Behind x_cavity = -(lip_thickness/2 + vestibule_depth) the cavity is a superellipse (half
  // width W, height roof - floor(x), exponent n) plus a vault bump V (1 - (y / 0.7 W)^2)^2, with
  // the floor linear in x, closed by the flat pharynx wall at x = -cavity_depth. Its volume:
  //   L [ 2 W (roof - mean floor) G + V 0.7 W 16/15 ],  G = Gamma(1+1/n)^2 / Gamma(1+2/n).
  MouthParams p;
  p.segments = 256;
  p.tongue = false;
  Mouth m = make_mouth(p);
  const double x0 = -(p.lip_thickness_m / 2 + p.vestibule_depth_m), x1 = -p.cavity_depth_m, L = x0 - x1;
  const double W = p.cavity_width_m / 2, n = p.cavity_exponent;
  const double mean_floor = -p.floor_depth_m + p.floor_rise_m / 2;
  const double expected = L * (2 * W * (p.palate_height_m - mean_floor) * gamma_ratio(n) + p.palate_vault_m * 0.7 * W * 16.0 / 15.0);
  // Mesh: the cavity parts' triangles behind x0, closed by a cone to a point on the plane x = x0
  // (whose own triangles lie in that plane and add nothing).
  const glm::dvec3 apex(x0, 0, 0);
  double vol = 0;
  for (const char* name : {"cheek_left", "palate", "cheek_right", "floor"}) {
    const TriangleMesh& t = part(m, name);
    for (size_t i = 0; i + 2 < t.indices.size(); i += 3) {
      glm::dvec3 a(t.positions[t.indices[i]]), b(t.positions[t.indices[i + 1]]), c(t.positions[t.indices[i + 2]]);
      if ((a.x + b.x + c.x) / 3 > x0) continue;
      vol += glm::dot(a - apex, glm::cross(b - apex, c - apex)) / 6.0;
    }
  }
  // The cavity's normals face into the air, i.e. into the enclosed region: negative volume.
  EXPECT_NEAR(-vol, expected, 0.01 * expected);
}

TEST(MeshMouth, ProceduralTongueVolumeTipAndUvs) {
  MouthParams p;
  p.segments = 192;
  p.tongue_protrusion_m = 0.012;
  p.tongue_pitch_deg = 10;
  TriangleMesh t = make_procedural_tongue(p);
  EXPECT_EQ(t.material, "tongue");
  EXPECT_TRUE(edge_stats(t).watertight());
  EXPECT_TRUE(edge_stats(t).consistently_oriented());
  // Taper, droop and pitch keep the superellipsoid's closed-form volume.
  TongueShape s = tongue_shape(p);
  const double a = p.tongue_length_m / 2, b = p.tongue_width_m / 2, c = p.tongue_thickness_m;
  double expected = 4 * a * b * c * std::tgamma(1 + 1 / s.p) * std::tgamma(1 + 1 / s.q) * std::tgamma(1 + 1 / s.r) /
                    std::tgamma(1 + 1 / s.p + 1 / s.q + 1 / s.r);
  EXPECT_NEAR(enclosed_volume(t), expected, 0.01 * expected);
  // The tip is at x = protrusion.
  EXPECT_NEAR(mesh_bounds(t).max.x, p.tongue_protrusion_m, 1e-6);
  EXPECT_TRUE(uv_range(t).within_unit_square());
  // Without pitch, the ring at mid-length (x = tip - length/2) is as wide as the parameter (the
  // taper is zero there) and sits at the given height.
  p.tongue_pitch_deg = 0;
  TriangleMesh u = make_procedural_tongue(p);
  const double xc = p.tongue_protrusion_m - p.tongue_length_m / 2;
  Bounds mid;
  for (auto& v : u.positions)
    if (std::abs(v.x - xc) < 1e-6) mid.add(glm::dvec3(v));
  EXPECT_NEAR(mid.size().y, p.tongue_width_m, 1e-3 * p.tongue_width_m);
  EXPECT_NEAR(mid.size().z, p.tongue_thickness_m, 1e-3 * p.tongue_thickness_m);
  EXPECT_NEAR(mid.max.z, p.tongue_center_z_m + p.tongue_thickness_m * p.tongue_dorsum_fraction, 1e-5);
}

TEST(MeshMouth, ParamsJsonRoundTripAndErrors) {
  MouthParams p;
  p.opening_m = 0.031;
  p.tongue = false;
  MouthParams q = mouth_params_from_json(to_json(p), "p.json");
  EXPECT_DOUBLE_EQ(q.opening_m, 0.031);
  EXPECT_FALSE(q.tongue);
  try {
    mouth_params_from_json({{"opening_mm", 30}}, "p.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/opening_mm");
  }
  try {
    mouth_params_from_json({{"opening_m", 0.5}}, "p.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/opening_m");
  }
  try {
    mouth_params_from_json({{"cavity_depth_m", 0.2}}, "p.json");  // deeper than the head block
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "/head_depth_m");
  }
}

TEST(MeshMouth, GlbKeepsPartsAnchorsAndParameters) {
  MouthParams p;
  p.segments = 32;
  auto file = std::filesystem::temp_directory_path() / "ofl_mouth.glb";
  write_glb(file, mouth_document(p));
  GltfContents g = read_gltf(file);
  EXPECT_EQ(g.meshes.size(), 8u);
  std::map<std::string, glm::dvec3> anchors;
  for (auto& a : g.anchors) anchors[a.name] = a.position;
  ASSERT_TRUE(anchors.count("opening_center"));
  ASSERT_TRUE(anchors.count("tongue_tip"));
  EXPECT_NEAR(anchors["tongue_tip"].x, p.tongue_protrusion_m, 1e-6);
  EXPECT_EQ(anchors["upper_teeth_slot"], glm::dvec3(0.0));
  EXPECT_DOUBLE_EQ(g.asset_extras.at("mouth_params").at("opening_m").get<double>(), p.opening_m);
}
