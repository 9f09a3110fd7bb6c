// Ctrl-C takes effect in every phase of a long job, not only between the passes of a render
// (docs/bad-inputs.md, "Interrupts"): in the middle of a render pass (the tiles not yet started skip
// it, the finished ones keep their samples), while a layered tissue's table is being filled at
// scene load, and while a large sweep checks its points before the first render. Each job is one
// that would go on for minutes after the signal if the phase did not check for it; the test sends
// SIGINT once the job's own progress says it is in that phase and then requires exit 130 with the
// message naming the phase (a guard of two minutes ends a job that ignores the signal; no time is
// asserted).
#include <gtest/gtest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "renderer/image/spectral_exr.h"
#include "tests/cli_runner.h"

extern char** environ;

namespace fs = std::filesystem;

namespace {

const std::string kSource = OFL_SOURCE_DIR;

struct Job {
  pid_t pid = -1;
  fs::path err, out;
};

// Starts `env... oralfluor args` with stdout and stderr in `dir`.
Job start(const std::string& env, const std::string& args, const fs::path& dir) {
  Job j;
  j.out = dir / "job.out";
  j.err = dir / "job.err";
  std::string cmd = "exec env -u OFL_NO_PROGRESS " + env + " " + std::string(OFL_BINARY) + " " + args + " > " + j.out.string() + " 2> " +
                    j.err.string();
  const char* argv[] = {"/bin/sh", "-c", cmd.c_str(), nullptr};
  posix_spawn(&j.pid, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ);
  return j;
}

// Waits until the job's stderr holds `text` (true) or the job ended or two minutes passed (false).
bool wait_for_text(const Job& j, const std::string& text) {
  for (int i = 0; i < 12000; ++i) {
    if (ofl::test::slurp(j.err).find(text) != std::string::npos) return true;
    int status = 0;
    if (::waitpid(j.pid, &status, WNOHANG) == j.pid) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

// SIGINT, then the exit code (-1: still running after two minutes, then killed).
int interrupt_and_wait(const Job& j) {
  ::kill(j.pid, SIGINT);
  for (int i = 0; i < 12000; ++i) {
    int status = 0;
    if (::waitpid(j.pid, &status, WNOHANG) == j.pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -2;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(j.pid, SIGKILL);
  ::waitpid(j.pid, nullptr, 0);
  return -1;
}

void write_json(const fs::path& p, const nlohmann::json& j) { std::ofstream(p) << j.dump(1); }

// A flat patch under `lights` LEDs: each camera sample evaluates every LED, so one pass of a large
// image takes seconds.
nlohmann::json patch_scene(int size, int spp, int lights, const nlohmann::json& material) {
  nlohmann::json s = {{"format", "oralfluor-scene"},
                      {"version", 1},
                      {"integrator", {{"spp", spp}, {"max_depth", 1}, {"output_bands", {{"min_nm", 500}, {"max_nm", 510}, {"step_nm", 10}}}}},
                      {"camera", {{"position", {0, 0, 0.3}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 20}, {"resolution", {size, size}}}},
                      {"materials", {{"patch", material}}},
                      {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.2, 0, 0}}, {"v", {0, 0.2, 0}}, {"material", "patch"}}}},
                      {"lights", nlohmann::json::array()}};
  for (int i = 0; i < lights; ++i) {
    double a = 6.283185307 * i / lights;
    s["lights"].push_back({{"spd", {{"type", "gaussian"}, {"peak_nm", 505}, {"fwhm_nm", 20}}},
                           {"radiant_intensity_W_sr", 0.01},
                           {"position", {0.05 * std::cos(a), 0.05 * std::sin(a), 0.1}},
                           {"target", {0, 0, 0}}});
  }
  return s;
}

}  // namespace

// The first pass of a 1024 x 1024 render under 400 LEDs (one sample per pixel, about a second):
// SIGINT as soon as its progress shows. The image keeps the tiles that finished the pass and nothing
// else: some pixels lit, some black, and render.json says 0 completed passes. Without the check per
// tile the pass would finish: every pixel lit, spp 1.
TEST(Interrupts, RenderStopsInsideAPassAndKeepsTheFinishedTiles) {
  const fs::path dir = ofl::test::fresh_dir("interrupt_render");
  write_json(dir / "scene.json", patch_scene(1024, 4, 400, {{"type", "lambertian"}, {"reflectance", 0.5}}));
  Job j = start("OFL_PROGRESS_SECONDS=0.05", "--threads 2 render " + (dir / "scene.json").string() + " -o " + (dir / "out").string(), dir);
  ASSERT_TRUE(wait_for_text(j, "render:  ")) << ofl::test::slurp(j.err);
  int code = interrupt_and_wait(j);
  ASSERT_EQ(code, 130) << ofl::test::slurp(j.err);
  auto info = nlohmann::json::parse(ofl::test::slurp(dir / "out" / "render.json"));
  EXPECT_EQ(info["interrupted"], true);
  EXPECT_EQ(info["spp"], 0) << "the pass in progress was completed after the signal\n" << ofl::test::slurp(j.err);
  ofl::SpectralImage img = ofl::read_spectral_exr(dir / "out" / "radiance.exr");
  size_t lit = 0, dark = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) (img.pixel(x, y)[0] > 0 ? lit : dark) += 1;
  EXPECT_GT(lit, 0u) << "the tiles that finished the interrupted pass keep their samples";
  EXPECT_GT(dark, 0u) << "the tiles not started skip the pass";
  fs::remove_all(dir);
}

// A layered tissue's table filled with 20000 walks per cosine and wavelength group (12 x 13 jobs of
// about a second: minutes on two cores): SIGINT once its progress shows.
TEST(Interrupts, LayeredTableFillStopsAtSigint) {
  const fs::path dir = ofl::test::fresh_dir("interrupt_table");
  write_json(dir / "scene.json", patch_scene(8, 1, 1, {{"type", "layered_tissue"}, {"preset", "lateral_tongue"}, {"table_photons", 20000}}));
  Job j = start("OFL_CACHE_DIR=off OFL_PROGRESS_SECONDS=0.05",
                "--threads 2 render " + (dir / "scene.json").string() + " -o " + (dir / "out").string(), dir);
  ASSERT_TRUE(wait_for_text(j, "layered table")) << ofl::test::slurp(j.err);
  int code = interrupt_and_wait(j);
  EXPECT_EQ(code, 130) << ofl::test::slurp(j.err);
  EXPECT_NE(ofl::test::slurp(j.err).find("interrupted: while filling a layered tissue's table"), std::string::npos)
      << ofl::test::slurp(j.err);
  EXPECT_FALSE(fs::exists(dir / "out" / "radiance.exr"));
  fs::remove_all(dir);
}

// A sweep whose parameter lists 4000 values checks 4000 points (one per value) before the first
// render, about 46 ms each: SIGINT during the check ends it there, nothing computed.
TEST(Interrupts, SweepStopsWhileCheckingItsPoints) {
  const fs::path dir = ofl::test::fresh_dir("interrupt_sweep");
  nlohmann::json values = nlohmann::json::array();
  for (int i = 0; i < 4000; ++i) values.push_back(20.0 + 40.0 * i / 4000);
  nlohmann::json sweep = {{"name", "big"},
                          {"scene", kSource + "/scenes/oraleye_385.json"},
                          {"camera", kSource + "/scenes/cameras/oraleye.json"},
                          {"render", {{"width", 48}, {"height", 36}, {"spp", 1}}},
                          {"design", {{"type", "latin_hypercube"}, {"points", 20000}}},
                          {"parameters", {{{"name", "half"}, {"generator", "led_half_angle"}, {"values", values}}}}};
  write_json(dir / "sweep.json", sweep);
  Job j = start("OFL_NO_PROGRESS=1", "sweep " + (dir / "sweep.json").string() + " -o " + (dir / "out").string(), dir);
  ASSERT_TRUE(wait_for_text(j, "checking 4000 of the 20000 points up front")) << ofl::test::slurp(j.err);
  int code = interrupt_and_wait(j);
  EXPECT_EQ(code, 130) << ofl::test::slurp(j.err);
  EXPECT_NE(ofl::test::slurp(j.err).find("interrupted: while checking the design points"), std::string::npos)
      << ofl::test::slurp(j.err);
  EXPECT_FALSE(fs::exists(dir / "out" / "points"));
  fs::remove_all(dir);
}
