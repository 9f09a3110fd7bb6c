// OBJ reader: counts, triangulation keeps the area, UV convention, and malformed files give an
// InputError naming the file and line (and exit code 2 from the CLI).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/wait.h>

#include "renderer/core/errors/error.h"
#include "renderer/mesh/geometry/mesh_measure.h"
#include "renderer/mesh/files/obj_reader.h"

using namespace ofl;

namespace {

std::string write_tmp(const std::string& name, const std::string& text) {
  auto p = std::filesystem::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p.string();
}

// A 2 x 3 x 4 box as six quads, with one UV per corner of each face (like the SOFA exports).
std::string box_obj() {
  return "# box\nv 0 0 0\nv 2 0 0\nv 2 3 0\nv 0 3 0\nv 0 0 4\nv 2 0 4\nv 2 3 4\nv 0 3 4\n"
         "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
         "g box\nusemtl skin\n"
         "f 1/1 4/4 3/3 2/2\nf 5/1 6/2 7/3 8/4\nf 1/1 2/2 6/3 5/4\nf 2/1 3/2 7/3 6/4\nf 3/1 4/2 8/3 7/4\nf 4/1 1/2 5/3 8/4\n";
}

}  // namespace

TEST(MeshObj, BoxCountsAreaVolumeAndUvFlip) {
  ObjContents c = parse_obj(box_obj(), "box.obj");
  ASSERT_EQ(c.meshes.size(), 1u);
  const TriangleMesh& m = c.meshes[0];
  EXPECT_EQ(m.name, "box");
  EXPECT_EQ(m.material, "skin");
  EXPECT_EQ(c.polygons_triangulated, 6u);
  EXPECT_EQ(m.triangle_count(), 12u);
  // Area 2 (2*3 + 2*4 + 3*4) = 52, volume 24: independent of how quads were split.
  EXPECT_NEAR(surface_area(m), 52.0, 1e-9);
  EXPECT_NEAR(enclosed_volume(m), 24.0, 1e-9);  // positive: faces wound outwards
  EXPECT_TRUE(edge_stats(m).watertight());
  EXPECT_TRUE(edge_stats(m).consistently_oriented());
  // glTF UVs: v flipped, so OBJ vt (0,0) becomes (0,1).
  bool found = false;
  for (size_t i = 0; i < m.positions.size(); ++i)
    if (m.positions[i] == glm::vec3(0, 0, 0) && m.uvs[i] == glm::vec2(0, 1)) found = true;
  EXPECT_TRUE(found);
  // Smooth normals of a corner point away from the box centre.
  for (size_t i = 0; i < m.positions.size(); ++i) {
    glm::vec3 d = m.positions[i] - glm::vec3(1, 1.5f, 2);
    EXPECT_GT(glm::dot(d, m.normals[i]), 0.0f);
  }
}

TEST(MeshObj, ConcavePolygonKeepsItsArea) {
  // An L-shaped hexagon (area 3) and a pentagon with negative (relative) indices (area 1.5).
  std::string text =
      "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n"
      "v 5 0 0\nv 6 0 0\nv 6 1 0\nv 5.5 2 0\nv 5 1 0\nf -5 -4 -3 -2 -1\n";
  ObjContents c = parse_obj(text, "poly.obj");
  ASSERT_EQ(c.meshes.size(), 1u);
  EXPECT_EQ(c.meshes[0].triangle_count(), 4u + 3u);
  EXPECT_NEAR(surface_area(c.meshes[0]), 3.0 + 1.5, 1e-9);
  EXPECT_EQ(c.positions, 11u);
}

TEST(MeshObj, GroupsAndMaterialsSplitMeshes) {
  std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\ng a\nusemtl red\nf 1 2 3\ng b\nf 1 2 4\nusemtl blue\nf 1 3 4\n";
  ObjContents c = parse_obj(text, "groups.obj");
  ASSERT_EQ(c.meshes.size(), 3u);
  EXPECT_EQ(c.meshes[0].name + "/" + c.meshes[0].material, "a/red");
  EXPECT_EQ(c.meshes[1].name + "/" + c.meshes[1].material, "b/red");
  EXPECT_EQ(c.meshes[2].name + "/" + c.meshes[2].material, "b/blue");
}

TEST(MeshObj, TrailingNulAndCommentsAreIgnored) {
  // The SOFA teeth.obj ends with a NUL byte and carries ZBrush "#MRGB" comment blocks.
  std::string text = "#MRGB ffe9ae84\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\n";
  text.push_back('\0');
  EXPECT_EQ(parse_obj(text, "nul.obj").meshes.at(0).triangle_count(), 1u);
}

namespace {
void expect_line_error(const std::string& text, const std::string& line, const std::string& fragment) {
  try {
    parse_obj(text, "bad.obj");
    FAIL() << "accepted: " << text;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "bad.obj");
    EXPECT_EQ(e.field(), line);
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}
}  // namespace

TEST(MeshObj, MalformedFilesNameTheLine) {
  expect_line_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "line 4", "out of range");
  expect_line_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "line 4", "out of range");
  expect_line_error("v 0 0 0\nv 1 zero 0\n", "line 2", "expected a number");
  expect_line_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/3\n", "line 5", "texture coordinate index 2");
  expect_line_error("v 0 0 0\nv 1 0 0\nf 1 2\n", "line 3", "at least 3");
  expect_line_error("v 0 0\n", "line 1", "x y z");
  expect_line_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "line 4", "integer");
  expect_line_error("v 0 0 nan\n", "line 1", "expected a number");
}

TEST(MeshObj, CliExitsWithCode2AndNamesFileAndLine) {
  std::string bad = write_tmp("ofl_bad_mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  std::string out = (std::filesystem::temp_directory_path() / "ofl_bad_mesh.glb").string();
  std::string cmd = std::string(OFL_BINARY) + " mesh convert " + bad + " -o " + out + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string text;
  char buf[512];
  while (fgets(buf, sizeof buf, pipe)) text += buf;
  int status = pclose(pipe);
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_NE(text.find(bad + ": line 4: "), std::string::npos) << text;
}
