// Sweep files and designs: full-grid size and order, Latin-hypercube stratification and
// determinism, level balance of lists in a hypercube, and errors that name the sweep file's field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "renderer/core/errors/error.h"
#include "renderer/sweep/design/sweep_design.h"
#include "renderer/sweep/design/sweep_spec.h"

using namespace ofl;

namespace {
const std::string kScenes = std::string(OFL_SOURCE_DIR) + "/scenes/";

// A sweep document in the scenes/sweeps folder (so relative paths resolve as for shipped sweeps).
SweepSpec spec_from(nlohmann::json j) {
  if (!j.contains("scene")) j["scene"] = "../oraleye_385.json";
  if (!j.contains("camera")) j["camera"] = "../cameras/oraleye.json";
  return parse_sweep_spec(JsonFile::from(j, kScenes + "sweeps/test.json"));
}

// The field an InputError names, or "" when parsing succeeds.
std::string error_field(const nlohmann::json& j) {
  try {
    spec_from(j);
  } catch (const InputError& e) {
    return e.field();
  }
  return "";
}
}  // namespace

TEST(SweepDesign, FullGridHasEveryCombinationLastFastest) {
  auto g = full_grid({3, 2, 4});
  ASSERT_EQ(g.size(), 24u);
  std::set<std::vector<int>> unique(g.begin(), g.end());
  EXPECT_EQ(unique.size(), 24u);
  EXPECT_EQ(g[0], (std::vector<int>{0, 0, 0}));
  EXPECT_EQ(g[1], (std::vector<int>{0, 0, 1}));
  EXPECT_EQ(g[4], (std::vector<int>{0, 1, 0}));
  EXPECT_EQ(g[8], (std::vector<int>{1, 0, 0}));
  EXPECT_EQ(g.back(), (std::vector<int>{2, 1, 3}));
}

TEST(SweepDesign, LatinHypercubeHasOneSampleInEveryStratumOfEveryDimension) {
  for (int n : {1, 7, 50}) {
    auto u = latin_hypercube(n, 4, 42);
    ASSERT_EQ(int(u.size()), n);
    for (int d = 0; d < 4; ++d) {
      std::vector<int> count(n, 0);
      for (int i = 0; i < n; ++i) {
        ASSERT_GE(u[i][d], 0.0);
        ASSERT_LT(u[i][d], 1.0);
        ++count[int(std::floor(u[i][d] * n))];
      }
      for (int k = 0; k < n; ++k) EXPECT_EQ(count[k], 1) << "n " << n << " dim " << d << " stratum " << k;
    }
  }
}

TEST(SweepDesign, LatinHypercubeIsDeterministicFromTheSeed) {
  EXPECT_EQ(latin_hypercube(20, 3, 7), latin_hypercube(20, 3, 7));
  EXPECT_NE(latin_hypercube(20, 3, 7), latin_hypercube(20, 3, 8));
  // Dimensions are paired by independent permutations, not all in the same order.
  auto u = latin_hypercube(20, 2, 7);
  int same = 0;
  for (auto& p : u) same += int(std::floor(p[0] * 20)) == int(std::floor(p[1] * 20));
  EXPECT_LT(same, 20);
}

TEST(SweepDesign, GridDesignFromASweepFile) {
  SweepSpec s = spec_from({{"parameters",
                            {{{"name", "leds"}, {"generator", "led_count"}, {"values", {4, 6, 8}}},
                             {{"name", "radius"}, {"generator", "ring_radius"}, {"range", {{"min", 0.005}, {"max", 0.015}, {"steps", 5}}}},
                             {{"name", "coat"}, {"variants", {{{"label", "wet"}}, {{"label", "dry"}, {"scene", {{"/materials/tongue/coating", false}}}}}}}}}});
  auto d = make_design(s);
  ASSERT_EQ(d.size(), 3u * 5u * 2u);
  EXPECT_DOUBLE_EQ(d[0].values[1].get<double>(), 0.005);
  EXPECT_DOUBLE_EQ(d[4 * 2].values[1].get<double>(), 0.015);
  EXPECT_NEAR(d[2].values[1].get<double>(), 0.0075, 1e-15);
  EXPECT_EQ(d[1].values[2], "dry");
  EXPECT_EQ(d.back().values[0], 8);
  for (size_t i = 0; i < d.size(); ++i) EXPECT_EQ(d[i].index, int(i));
}

TEST(SweepDesign, LatinHypercubeSpreadsRangesAndBalancesLevels) {
  SweepSpec s = spec_from({{"design", {{"type", "latin_hypercube"}, {"points", 12}, {"seed", 3}}},
                           {"parameters",
                            {{{"name", "tilt"}, {"generator", "led_tilt"}, {"range", {{"min", 0}, {"max", 30}}}},
                             {{"name", "half"}, {"generator", "led_half_angle"}, {"values", {15, 30, 45}}},
                             {{"name", "leds"}, {"generator", "led_count"}, {"range", {{"min", 3}, {"max", 8}, {"integer", true}}}}}}});
  auto d = make_design(s);
  ASSERT_EQ(d.size(), 12u);
  std::vector<int> strata(12, 0), levels(3, 0), leds(9, 0);
  for (auto& p : d) {
    double t = p.values[0].get<double>();
    ASSERT_GE(t, 0.0);
    ASSERT_LT(t, 30.0);
    ++strata[int(std::floor(t / 30.0 * 12))];
    EXPECT_EQ(p.level[0], -1);
    ++levels[p.level[1]];
    ASSERT_TRUE(p.values[2].is_number_integer());
    ++leds[p.values[2].get<int>()];
  }
  for (int c : strata) EXPECT_EQ(c, 1);
  for (int c : levels) EXPECT_EQ(c, 4);   // 12 points over 3 levels
  for (int k = 3; k <= 8; ++k) EXPECT_EQ(leds[k], 2);  // 12 points over the 6 integers 3..8
}

TEST(SweepDesign, ErrorsNameTheFieldOfTheSweepFile) {
  nlohmann::json ok_param = {{"name", "leds"}, {"generator", "led_count"}, {"values", {4, 6}}};
  EXPECT_EQ(error_field({{"parameters", {ok_param}}}), "");
  EXPECT_EQ(error_field({{"parameters", {ok_param}}, {"rendr", {}}}), "/rendr");
  EXPECT_EQ(error_field({{"parameters", {{{"name", "x"}, {"generator", "led_cuont"}, {"values", {1}}}}}}), "/parameters/0/generator");
  EXPECT_EQ(error_field({{"parameters", {ok_param, ok_param}}}), "/parameters/1/name");
  EXPECT_EQ(error_field({{"parameters", {{{"name", "leds"}, {"generator", "led_count"}, {"values", {4, 5.5}}}}}}),
            "/parameters/0/values/1");
  EXPECT_EQ(error_field({{"parameters", {{{"name", "r"}, {"scene", "lights/0"}, {"values", {1}}}}}}), "/parameters/0/scene");
  EXPECT_EQ(error_field({{"parameters", {{{"name", "r"}, {"scene", "/a"}, {"range", {{"min", 2}, {"max", 1}}}}}}}),
            "/parameters/0/range/max");
  EXPECT_EQ(error_field({{"parameters", {ok_param}}, {"design", {{"type", "latin_hypercube"}}}}), "/design/points");
  EXPECT_EQ(error_field({{"parameters", {ok_param}}, {"lesion_contrast", {{"lesion", "nope"}, {"healthy", "tongue"}}}}),
            "/lesion_contrast/lesion");
  EXPECT_EQ(error_field({{"parameters", {ok_param}}, {"camera", "../cameras/missing.json"}}), "/camera");
}
