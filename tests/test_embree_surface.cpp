// EmbreeScene::surface: a hit on a flat mesh without normals or texture coordinates takes its
// geometric normal from Embree instead of the triangle's vertices; it must be the same unit normal,
// with the same orientation (cross(p1 - p0, p2 - p0), which "front side as authored" relies on),
// and the hit point (o + t d) must lie on the triangle's plane well within the ray offset
// (EmbreeScene::offset: 1e-5 of the point's largest coordinate).
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "renderer/render/trace/embree_scene.h"
#include "renderer/render/trace/rng.h"

using namespace ofl;

TEST(EmbreeSurface, FlatMeshNormalFromEmbreeEqualsTheVertexNormal) {
  Scene sc;
  sc.materials.emplace_back();
  Rng r(5, 9);
  for (int t = 0; t < 20; ++t) {  // 20 random triangles, each its own mesh, far apart
    TriangleMesh m;
    m.material_id = 0;
    const glm::vec3 c(0.3f * t, 0.0f, 0.0f);
    for (int k = 0; k < 3; ++k)
      m.positions.push_back(c + glm::vec3(0.1f * float(r.next_double() - 0.5), 0.1f * float(r.next_double() - 0.5), 0.1f * float(r.next_double() - 0.5)));
    m.indices = {0, 1, 2};
    sc.meshes.push_back(m);
  }
  EmbreeScene es(sc);
  int hits = 0;
  for (int t = 0; t < 20; ++t) {
    const auto& P = sc.meshes[t].positions;
    const glm::dvec3 p0(P[0]), p1(P[1]), p2(P[2]);
    const glm::dvec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    const glm::dvec3 target = (p0 + p1 + p2) / 3.0;
    for (double side : {1.0, -1.0}) {  // from the front and from the back
      const glm::dvec3 o = target + side * 0.05 * n + glm::dvec3(0.001, -0.002, 0.0015);
      const glm::dvec3 d = glm::normalize(target - o);
      RayHit h = es.intersect(o, d);
      ASSERT_TRUE(h.found());
      SurfacePoint s = es.surface(h, o, d);
      EXPECT_NEAR(glm::dot(s.ng, n), 1.0, 1e-6);
      EXPECT_EQ(s.ns, s.ng);
      EXPECT_NEAR(glm::dot(s.p - p0, n), 0.0, 1e-6 * s.scale);
      ++hits;
    }
  }
  EXPECT_EQ(hits, 40);
}

// EmbreeScene::outward_face: on a lone flat square every continuation on the side of the normal
// leaves the scene (both sides, checked against leaves_scene for many directions); with anything
// above the square's plane it is not an outward face any more.
TEST(EmbreeSurface, OutwardFaceOnlyWhereEveryContinuationLeaves) {
  auto square = [](float z) {
    TriangleMesh m;
    m.material_id = 0;
    m.positions = {{-0.05f, -0.05f, z}, {0.05f, -0.05f, z}, {-0.05f, 0.05f, z}, {0.05f, 0.05f, z}};
    m.indices = {0, 1, 2, 2, 1, 3};
    return m;
  };
  Scene flat;
  flat.materials.emplace_back();
  flat.meshes.push_back(square(0.0f));
  EmbreeScene es(flat);
  Rng r(3, 7);
  for (double side : {1.0, -1.0}) {
    const glm::dvec3 o(0.01, -0.02, 0.3 * side), d = glm::normalize(glm::dvec3(0.003, 0.001, 0) - o);
    RayHit h = es.intersect(o, d);
    ASSERT_TRUE(h.found());
    SurfacePoint s = es.surface(h, o, d);
    if (glm::dot(s.ng, -d) < 0) s.ng = -s.ng;  // as the path tracer turns it toward the viewer
    ASSERT_TRUE(es.outward_face(s));
    for (int i = 0; i < 2000; ++i) {
      glm::dvec3 w = glm::normalize(glm::dvec3(r.next_double() - 0.5, r.next_double() - 0.5, r.next_double() - 0.5));
      if (glm::dot(w, s.ng) <= 0) w = -w;
      if (glm::dot(w, s.ng) <= 0) continue;
      EXPECT_TRUE(es.leaves_scene(EmbreeScene::offset(s, w), w));
    }
  }
  Scene two = flat;
  two.meshes.push_back(square(0.02f));  // a second square above: the lower one faces it
  EmbreeScene es2(two);
  const glm::dvec3 o(0.01, -0.02, -0.3), d = glm::normalize(glm::dvec3(0.003, 0.001, 0) - o);
  RayHit h = es2.intersect(o, d);
  ASSERT_TRUE(h.found());
  SurfacePoint s = es2.surface(h, o, d);
  EXPECT_FALSE(es2.outward_face(s));  // from below, the normal as authored points up, at the other square
  s.ng = -s.ng;
  EXPECT_TRUE(es2.outward_face(s));   // turned toward the viewer below: nothing lies below z = 0
}
