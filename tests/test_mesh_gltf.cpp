// OBJ -> glTF binary -> back: counts, bounding box, area and UVs survive the round trip and the
// change of units/axes; the shipped SOFA meshes have the documented scale and frame.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "renderer/core/files/asset_path.h"
#include "renderer/core/errors/error.h"
#include "renderer/mesh/files/gltf_reader.h"
#include "renderer/mesh/files/gltf_writer.h"
#include "renderer/mesh/files/mesh_convert.h"
#include "renderer/mesh/geometry/mesh_measure.h"

using namespace ofl;

namespace {

std::filesystem::path tmp(const std::string& name) { return std::filesystem::temp_directory_path() / name; }

// Two groups: a 2 x 3 x 4 box of quads (area 52) and a separate unit right triangle (area 0.5)
// at x = 10, with UVs on the box.
std::string two_group_obj() {
  return "v 0 0 0\nv 2 0 0\nv 2 3 0\nv 0 3 0\nv 0 0 4\nv 2 0 4\nv 2 3 4\nv 0 3 4\n"
         "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.25 0.75\n"
         "g box\nf 1/1 4/4 3/3 2/2\nf 5/1 6/2 7/3 8/4\nf 1/1 2/2 6/3 5/4\nf 2/1 3/2 7/3 6/4\nf 3/1 4/2 8/3 7/4\nf 4/1 1/2 5/3 8/4\n"
         "v 10 0 0\nv 11 0 0\nv 10 1 0\ng tri\nf 9/5 10/5 11/5\n";
}

}  // namespace

TEST(MeshGltf, ObjRoundTripKeepsCountsBoundsAreaUvs) {
  auto obj = tmp("ofl_roundtrip.obj");
  std::ofstream(obj) << two_group_obj();
  ConvertOptions opt;
  opt.scale = 0.01;              // centimetre-like units -> metres
  opt.axes = "-z,x,-y";          // new x = -old z, new y = old x, new z = -old y (a rotation)
  opt.material_name = "tissue";
  ConvertReport rep;
  GlbDocument doc = convert_obj(obj, opt, &rep);
  auto glb = tmp("ofl_roundtrip.glb");
  write_glb(glb, doc);
  GltfContents back = read_gltf(glb);

  ASSERT_EQ(back.meshes.size(), 2u);  // one per OBJ group
  size_t verts = 0, tris = 0;
  double area = 0;
  for (auto& m : back.meshes) {
    EXPECT_EQ(m.material, "tissue");
    verts += m.vertex_count();
    tris += m.triangle_count();
    area += surface_area(m);
  }
  EXPECT_EQ(verts, rep.vertices);
  EXPECT_EQ(tris, 12u + 1u);
  // 24 face corners of the box, of which 4 (position, UV) pairs repeat in a second face
  // ((1,1), (2,2), (7,3), (8,4)): 20 vertices; and 3 for the triangle.
  EXPECT_EQ(verts, 20u + 3u);
  // Area scales with scale^2: (52 + 0.5) * 1e-4 m^2, computed from the box's sides.
  EXPECT_NEAR(area, (2 * (2 * 3 + 2 * 4 + 3 * 4) + 0.5) * 1e-4, 1e-9);
  // Bounds: old x in [0, 11], y in [0, 3], z in [0, 4] -> new x = -z in [-4, 0], y = x in
  // [0, 11], z = -y in [-3, 0]; times 0.01.
  Bounds b = mesh_bounds(back.meshes);
  EXPECT_NEAR(b.min.x, -0.04, 1e-7);
  EXPECT_NEAR(b.max.x, 0.0, 1e-7);
  EXPECT_NEAR(b.min.y, 0.0, 1e-7);
  EXPECT_NEAR(b.max.y, 0.11, 1e-7);
  EXPECT_NEAR(b.min.z, -0.03, 1e-7);
  EXPECT_NEAR(b.max.z, 0.0, 1e-7);
  // A rotation keeps the box closed and outward-facing: volume 24 cm^3.
  for (auto& m : back.meshes)
    if (m.name == "box") {
      EXPECT_TRUE(edge_stats(m).watertight());
      EXPECT_NEAR(enclosed_volume(m), 24e-6, 1e-10);  // float positions
      EXPECT_TRUE(uv_range(m).within_unit_square());
    } else {
      // OBJ vt (0.25, 0.75) -> glTF (0.25, 0.25).
      EXPECT_NEAR(m.uvs.at(0).x, 0.25, 1e-7);
      EXPECT_NEAR(m.uvs.at(0).y, 0.25, 1e-7);
    }
  EXPECT_NEAR(back.asset_extras.at("metres_per_source_unit").get<double>(), 0.01, 1e-15);
}

TEST(MeshGltf, TargetWidthAndMergeAndCenter) {
  auto obj = tmp("ofl_width.obj");
  std::ofstream(obj) << two_group_obj();
  ConvertOptions opt;
  opt.target_width_m = 0.05;  // old x extent 11 -> 5 cm
  opt.width_axis = 0;
  opt.merge = true;
  opt.center = true;
  ConvertReport rep;
  GlbDocument doc = convert_obj(obj, opt, &rep);
  ASSERT_EQ(doc.meshes.size(), 1u);
  EXPECT_NEAR(rep.scale, 0.05 / 11, 1e-12);
  Bounds b = mesh_bounds(doc.meshes);
  EXPECT_NEAR(b.size().x, 0.05, 1e-7);
  EXPECT_NEAR(b.center().x, 0.0, 1e-7);
  EXPECT_NEAR(b.center().z, 0.0, 1e-7);
}

TEST(MeshGltf, AxesAndRotationSpecs) {
  glm::dmat3 m = parse_axes("-z,x,-y");
  glm::dvec3 v = m * glm::dvec3(1, 2, 3);
  EXPECT_EQ(v, glm::dvec3(-3, 1, -2));
  glm::dvec3 r = parse_rotation("y:90") * glm::dvec3(0, 0, 1);  // right-handed about y: z -> x
  EXPECT_NEAR(r.x, 1, 1e-12);
  EXPECT_NEAR(r.z, 0, 1e-12);
  EXPECT_THROW(parse_axes("x,x,z"), InputError);
  EXPECT_THROW(parse_axes("x,y"), InputError);
  EXPECT_THROW(parse_rotation("w:10"), InputError);
}

TEST(MeshGltf, AnchorsAndExtrasSurvive) {
  GlbDocument doc;
  TriangleMesh t;
  t.name = "tri";
  t.material = "tongue";
  t.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  t.indices = {0, 1, 2};
  doc.meshes.push_back(t);
  doc.anchors.push_back({"slot", {0.1, -0.2, 0.3}});
  doc.extras = {{"k", 1.5}};
  auto glb = tmp("ofl_anchor.glb");
  write_glb(glb, doc);
  GltfContents back = read_gltf(glb);
  ASSERT_EQ(back.anchors.size(), 1u);
  EXPECT_EQ(back.anchors[0].name, "slot");
  EXPECT_NEAR(back.anchors[0].position.y, -0.2, 1e-12);
  EXPECT_EQ(back.meshes.at(0).material, "tongue");
  EXPECT_DOUBLE_EQ(back.asset_extras.at("k").get<double>(), 1.5);
}

// The shipped, converted SOFA meshes (assets/meshes): real scale and the documented frame.
TEST(MeshGltf, ShippedTongueIsAdultSizedInTheMouthFrame) {
  GltfContents t = read_gltf(asset_path("meshes/tongue.glb"));
  ASSERT_EQ(t.meshes.size(), 1u);
  const TriangleMesh& m = t.meshes[0];
  EXPECT_EQ(m.material, "tongue");
  Bounds b = mesh_bounds(m);
  // Width (along y, the patient's left-right) of an adult tongue: 4-6 cm.
  EXPECT_GT(b.size().y, 0.04);
  EXPECT_LT(b.size().y, 0.06);
  // Closed, outward-facing, UVs kept and within [0,1].
  EXPECT_TRUE(edge_stats(m).watertight());
  EXPECT_GT(enclosed_volume(m), 0);
  ASSERT_EQ(m.uvs.size(), m.positions.size());
  EXPECT_TRUE(uv_range(m).within_unit_square());
  // Inside the mouth: behind the lip plane (x < 0), roughly centred left-right.
  EXPECT_LT(b.max.x, 0.0);
  EXPECT_NEAR(b.center().y, 0.0, 0.003);
}

TEST(MeshGltf, ShippedTeethShareTheTongueScale) {
  GltfContents teeth = read_gltf(asset_path("meshes/teeth.glb"));
  GltfContents tongue = read_gltf(asset_path("meshes/tongue.glb"));
  ASSERT_FALSE(teeth.meshes.empty());
  EXPECT_EQ(teeth.meshes[0].material, "teeth");
  // One scale factor for both (recorded by the converter).
  EXPECT_DOUBLE_EQ(teeth.asset_extras.at("metres_per_source_unit").get<double>(),
                   tongue.asset_extras.at("metres_per_source_unit").get<double>());
  // Source extents (arbitrary units): tongue width 1.7994, arch width 2.7995 -> their ratio.
  Bounds bt = mesh_bounds(teeth.meshes), bg = mesh_bounds(tongue.meshes);
  EXPECT_NEAR(bt.size().y / bg.size().y, 2.7995 / 1.7994, 2e-3);
  // The front teeth are just behind the lips (x < 0) and the tongue tip behind them.
  EXPECT_LT(bt.max.x, 0.0);
  EXPECT_LT(bg.max.x, bt.max.x);
}
