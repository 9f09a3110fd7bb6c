// Large sweeps are sized before they start and share a folder safely (docs/sweep-format.md, "Size"
// and "Several sweeps in one folder"): the keys computed for many points at once equal each point's
// own key; a large design checks one point per level of every parameter (and each range's extremes)
// up front instead of every point; the documented limit is enforced and a dry run of a design at the
// limit answers without loading every point; a run says how long a point takes; two sweeps started
// together into one folder compute every point exactly once between them.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <fstream>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "renderer/core/errors/error.h"
#include "renderer/sweep/design/sweep_design.h"
#include "renderer/sweep/design/sweep_spec.h"
#include "renderer/sweep/sweep_point.h"
#include "renderer/sweep/sweep_runner.h"
#include "tests/cli_runner.h"

using namespace ofl;
namespace fs = std::filesystem;

namespace {

const std::string kSource = OFL_SOURCE_DIR;

SweepSpec spec_from(nlohmann::json j) {
  if (!j.contains("scene")) j["scene"] = "../oraleye_385.json";
  if (!j.contains("camera")) j["camera"] = "../cameras/oraleye.json";
  return parse_sweep_spec(JsonFile::from(j, kSource + "/scenes/sweeps/test.json"));
}

nlohmann::json values(int n, double lo, double step) {
  nlohmann::json v = nlohmann::json::array();
  for (int i = 0; i < n; ++i) v.push_back(lo + step * i);
  return v;
}

}  // namespace

TEST(SweepSize, KeysOfManyPointsEqualEachPointsOwnKey) {
  for (const char* file : {"tiny.json", "led_ring.json", "invariance.json"}) {
    SweepSpec spec = load_sweep_spec(kSource + "/scenes/sweeps/" + file);
    auto design = make_design(spec);
    PointKeys keys(spec);
    std::set<std::string> distinct;
    for (const auto& p : design) {
      std::string k = keys.key(p);
      EXPECT_EQ(k, point_key(spec, p)) << file << " point " << p.index;
      distinct.insert(k);
    }
    EXPECT_EQ(distinct.size(), design.size()) << file;
  }
}

TEST(SweepSize, LargeDesignChecksEveryLevelOfEveryParameterUpFront) {
  // A grid of 6 x 5 x 4 = 120 points (more than are all checked): one point per level.
  SweepSpec grid = spec_from({{"parameters",
                               {{{"name", "a"}, {"generator", "led_count"}, {"values", {3, 4, 5, 6, 7, 8}}},
                                {{"name", "b"}, {"generator", "rig_distance"}, {"values", values(5, 0.07, 0.005)}},
                                {{"name", "c"}, {"generator", "led_half_angle"}, {"values", values(4, 20, 10)}}}}});
  auto design = make_design(grid);
  ASSERT_EQ(design.size(), 120u);
  ASSERT_GT(design.size(), size_t(kCheckAllPointsUpTo));
  auto checked = points_checked_up_front(grid, design);
  EXPECT_LE(checked.size(), 6u + 5u + 4u);
  for (size_t pi = 0; pi < 3; ++pi) {
    std::set<int> levels;
    for (int i : checked) levels.insert(design[size_t(i)].level[pi]);
    EXPECT_EQ(int(levels.size()), grid.parameters[pi].levels()) << "parameter " << pi;
  }
  // A Latin hypercube over ranges: the points with each range's smallest and largest value.
  SweepSpec lhs = spec_from({{"design", {{"type", "latin_hypercube"}, {"points", 5000}, {"seed", 7}}},
                             {"parameters",
                              {{{"name", "d"}, {"generator", "rig_distance"}, {"range", {{"min", 0.07}, {"max", 0.1}}}},
                               {{"name", "h"}, {"generator", "led_half_angle"}, {"range", {{"min", 20}, {"max", 60}}}}}}});
  auto d2 = make_design(lhs);
  auto c2 = points_checked_up_front(lhs, d2);
  EXPECT_LE(c2.size(), 4u);
  for (size_t pi = 0; pi < 2; ++pi) {
    double lo = 1e30, hi = -1e30, clo = 1e30, chi = -1e30;
    for (auto& p : d2) lo = std::min(lo, p.values[pi].get<double>()), hi = std::max(hi, p.values[pi].get<double>());
    for (int i : c2) clo = std::min(clo, d2[size_t(i)].values[pi].get<double>()), chi = std::max(chi, d2[size_t(i)].values[pi].get<double>());
    EXPECT_EQ(clo, lo);
    EXPECT_EQ(chi, hi);
  }
  // A small design is checked whole.
  SweepSpec small = load_sweep_spec(kSource + "/scenes/sweeps/tiny.json");
  EXPECT_EQ(points_checked_up_front(small, make_design(small)).size(), 4u);
}

TEST(SweepSize, TheLimitIsEnforcedForGridsAndHypercubes) {
  auto field = [](const nlohmann::json& j) {
    try {
      spec_from(j);
    } catch (const InputError& e) {
      return e.field() + ": " + e.what();
    }
    return std::string();
  };
  // 320 x 320 = 102400 grid points, one more parameter level than the limit allows.
  nlohmann::json big = {{"parameters",
                         {{{"name", "a"}, {"generator", "rig_distance"}, {"values", values(320, 0.07, 1e-5)}},
                          {{"name", "b"}, {"generator", "led_half_angle"}, {"values", values(320, 20, 0.1)}}}}};
  EXPECT_NE(field(big).find("the full grid has 102400 points, more than the 100000"), std::string::npos) << field(big);
  nlohmann::json lhs = big;
  lhs["design"] = {{"type", "latin_hypercube"}, {"points", kMaxSweepPoints + 1}};
  EXPECT_NE(field(lhs).find("/design/points"), std::string::npos) << field(lhs);
  lhs["design"]["points"] = kMaxSweepPoints;
  EXPECT_EQ(field(lhs), "");
}

// A dry run of a design at the limit: every key, no point loaded beyond the four the check picks.
// (Loading all 100000 points took about 46 ms each: over an hour.)
TEST(SweepSize, DryRunOfTheLargestDesignListsCountsWithoutLoadingEveryPoint) {
  const fs::path dir = ofl::test::fresh_dir("sweep_size_dry");
  nlohmann::json j = nlohmann::json::parse(ofl::test::slurp(kSource + "/scenes/sweeps/tiny.json"));
  j["scene"] = kSource + "/scenes/lesion_385.json";
  j["camera"] = kSource + "/scenes/cameras/oraleye.json";
  for (auto& r : j["rois"])
    if (r.contains("texture")) r["texture"] = kSource + "/assets/textures/tongue_lesion.png";
  j["design"] = {{"type", "latin_hypercube"}, {"points", kMaxSweepPoints}, {"seed", 3}};
  j["parameters"] = {{{"name", "distance_m"}, {"generator", "rig_distance"}, {"range", {{"min", 0.07}, {"max", 0.1}}}},
                     {{"name", "half"}, {"generator", "led_half_angle"}, {"range", {{"min", 20}, {"max", 60}}}}};
  std::ofstream(dir / "big.json") << j.dump(1);
  auto r = ofl::test::run_cli("sweep " + (dir / "big.json").string() + " -o " + (dir / "out").string() + " --dry-run");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("checking 4 of the 100000 points up front"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("100000 points in the design, 100000 in this shard: 0 done, 100000 to compute"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("... 99980 more points not listed"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
  fs::remove_all(dir);
}

// Two sweeps started together into one folder: between them every point is computed exactly once,
// each says how long a point takes, and the one that finishes last reports all four points.
TEST(SweepSize, TwoSweepsInOneFolderComputeEveryPointOnce) {
  const fs::path dir = ofl::test::fresh_dir("sweep_size_two");
  const std::string args = "sweep " + kSource + "/scenes/sweeps/tiny.json -o " + (dir / "out").string() + " --json";
  const std::string a = std::string(OFL_BINARY) + " " + args + " > " + (dir / "a.json").string() + " 2> " + (dir / "a.err").string();
  const std::string b = std::string(OFL_BINARY) + " " + args + " > " + (dir / "b.json").string() + " 2> " + (dir / "b.err").string();
  int status = std::system(("OFL_NO_PROGRESS=1 sh -c '" + a + " & " + b + "; wait'").c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  auto sa = nlohmann::json::parse(ofl::test::slurp(dir / "a.json"));
  auto sb = nlohmann::json::parse(ofl::test::slurp(dir / "b.json"));
  EXPECT_EQ(sa["computed"].get<int>() + sb["computed"].get<int>(), 4)
      << ofl::test::slurp(dir / "a.err") << ofl::test::slurp(dir / "b.err");
  EXPECT_EQ(std::max(sa["finished"].get<int>(), sb["finished"].get<int>()), 4);
  std::ifstream csv(dir / "out" / "results.csv");
  int lines = 0;
  for (std::string l; std::getline(csv, l);) ++lines;
  EXPECT_EQ(lines, 5) << "header and the four points";
  const std::string errs = ofl::test::slurp(dir / "a.err") + ofl::test::slurp(dir / "b.err");
  EXPECT_NE(errs.find("a point takes about"), std::string::npos) << errs;
  EXPECT_TRUE(ofl::test::temporaries(dir / "out").empty());
  fs::remove_all(dir);
}
