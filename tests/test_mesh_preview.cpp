// The preview rasteriser used to check mesh placement: coverage equals projected area.
#include <gtest/gtest.h>

#include "renderer/mesh/mesh_preview.h"

using namespace ofl;

TEST(MeshPreview, OrthographicCoverageEqualsProjectedArea) {
  // A 1 x 1 square in the y-z plane seen from +x in a view 2 units high: a quarter of the pixels.
  TriangleMesh sq;
  sq.material = "tongue";
  sq.positions = {{0, -0.5f, -0.5f}, {0, 0.5f, -0.5f}, {0, 0.5f, 0.5f}, {0, -0.5f, 0.5f}};
  sq.indices = {0, 1, 2, 0, 2, 3};
  PreviewCamera cam = named_view("front");
  cam.ortho_height = 2;
  PreviewOptions opt;
  opt.width = opt.height = 200;
  std::vector<float> img = render_preview({sq}, cam, opt);
  size_t lit = 0;
  for (size_t i = 0; i < img.size(); i += 3)
    if (img[i] != static_cast<float>(opt.background.x)) ++lit;
  EXPECT_NEAR(static_cast<double>(lit) / (200 * 200), 0.25, 0.25 * 0.02);
}

TEST(MeshPreview, ClipSpecs) {
  ClipPlane c = parse_clip("y>0.01");
  EXPECT_EQ(c.axis, 1);
  EXPECT_FALSE(c.keep_below);
  EXPECT_DOUBLE_EQ(c.value, 0.01);
  EXPECT_THROW(parse_clip("q<1"), std::exception);
}
