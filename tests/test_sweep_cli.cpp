// `oralfluor sweep` end to end on tiny renders (48 x 36 pixels, 8 samples per pixel): the HTML
// report loads in headless Chromium and shows every plot; a sweep killed with SIGKILL resumes with
// only the missing points, without recomputing or duplicating finished ones; SIGINT saves and exits
// 130; shards partition the design; mpirun -np 2 spreads the points over two ranks and gathers
// exactly the results a single process computes; bad sweep files exit 2 naming the field.
#include <gtest/gtest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "sanitizer_scale.h"

#include "renderer/sweep/design/sweep_spec.h"

extern char** environ;

namespace {

const std::string kSource = OFL_SOURCE_DIR;
const std::string kTiny = kSource + "/scenes/sweeps/tiny.json";

std::filesystem::path fresh(const std::string& name) { return ofl::test::fresh_dir("sweep_cli_" + name); }
using ofl::test::slurp;

struct CmdResult {
  int code = -1;
  std::string out, err;
};

// Runs a shell command line with stdout and stderr captured in `dir`.
CmdResult sh(const std::string& cmd, const std::filesystem::path& dir, const std::string& tag = "run") {
  auto out = dir / (tag + ".out"), err = dir / (tag + ".err");
  int status = std::system((cmd + " > " + out.string() + " 2> " + err.string()).c_str());
  CmdResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

CmdResult sweep(const std::string& args, const std::filesystem::path& dir, const std::string& tag = "run") {
  return sh(std::string(OFL_BINARY) + " sweep " + args, dir, tag);
}

// Starts the sweep in the background (for the kill tests); returns its pid.
pid_t start_sweep(const std::string& args, const std::filesystem::path& dir) {
  std::string cmd = "exec " + std::string(OFL_BINARY) + " sweep " + args + " > " + (dir / "bg.out").string() + " 2> " +
                    (dir / "bg.err").string();
  pid_t pid = -1;
  const char* argv[] = {"/bin/sh", "-c", cmd.c_str(), nullptr};
  posix_spawn(&pid, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ);
  return pid;
}

std::vector<std::filesystem::path> point_files(const std::filesystem::path& out) {
  std::vector<std::filesystem::path> v;
  std::error_code ec;
  for (auto& e : std::filesystem::directory_iterator(out / "points", ec)) {
    std::string n = e.path().filename().string();
    if (n[0] != '.' && e.path().extension() == ".json") v.push_back(e.path());
  }
  std::sort(v.begin(), v.end());
  return v;
}

int temporaries(const std::filesystem::path& out) {
  int n = 0;
  std::error_code ec;
  for (auto& e : std::filesystem::directory_iterator(out / "points", ec)) n += e.path().extension() == ".tmp";
  return n;
}

// Waits (up to two minutes) until at least `n` points are stored.
bool wait_for_points(const std::filesystem::path& out, size_t n) {
  for (int i = 0; i < 6000; ++i) {
    if (point_files(out).size() >= n) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

// The CSV's rows as column -> value maps.
std::vector<std::map<std::string, std::string>> read_csv(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string line;
  std::vector<std::string> head;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& s) {
    std::vector<std::string> f;
    std::string cur;
    for (char c : s) {
      if (c == ',') {
        f.push_back(cur);
        cur.clear();
      } else {
        cur += c;
      }
    }
    f.push_back(cur);
    return f;
  };
  if (std::getline(in, line)) head = split(line);
  while (std::getline(in, line)) {
    auto f = split(line);
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < head.size() && i < f.size(); ++i) row[head[i]] = f[i];
    rows.push_back(row);
  }
  return rows;
}

// A sweep over the LED count of the default scene, tiny renders, written into `dir`.
std::filesystem::path led_count_sweep(const std::filesystem::path& dir, std::vector<int> counts) {
  nlohmann::json j = {{"name", "count"},
                      {"scene", kSource + "/scenes/oraleye_385.json"},
                      {"camera", kSource + "/scenes/cameras/oraleye.json"},
                      {"render", {{"width", 48}, {"height", 36}, {"spp", 8}, {"max_depth", 3}}},
                      {"parameters", {{{"name", "leds"}, {"generator", "led_count"}, {"values", counts}}}}};
  auto f = dir / "count.json";
  std::ofstream(f) << j.dump(1);
  return f;
}

struct FileState {
  std::string bytes;
  int64_t mtime_ns = 0;
};
FileState state_of(const std::filesystem::path& p) {
  struct stat st {};
  ::stat(p.c_str(), &st);
  return {slurp(p), int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
}

}  // namespace

TEST(SweepCli, ReportOpensInHeadlessChromiumAndShowsEveryPlot) {
  auto dir = fresh("report");
  CmdResult r = sweep(kTiny + " -o " + (dir / "out").string() + " --json", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  auto summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["finished"], 4);
  auto rows = read_csv(dir / "out" / "results.csv");
  ASSERT_EQ(rows.size(), 4u);
  for (auto& row : rows) {
    // Every ROI, the lesion contrast and the signal shares are there.
    for (const char* c : {"dorsum.irr_cv", "lesion.r_std", "teeth.share_leak", "contrast.mahalanobis", "dorsum.snr_G"})
      EXPECT_FALSE(row[c].empty()) << c;
    double shares = std::stod(row["dorsum.share_fluorescence"]) + std::stod(row["dorsum.share_reflected"]) +
                    std::stod(row["dorsum.share_leak"]);
    EXPECT_NEAR(shares, 1.0, 1e-9);
  }

  // Expected plots: every report metric of every ROI against each of the 2 parameters, plus one
  // chromaticity scatter per point.
  ofl::SweepSpec spec = ofl::load_sweep_spec(kTiny);
  const int expected = int(spec.rois.size() * spec.report.metrics.size() * spec.parameters.size()) + 4;
  std::string html = slurp(dir / "out" / "report.html");
  int in_source = 0;
  for (size_t p = html.find("<svg class=\"plot\""); p != std::string::npos; p = html.find("<svg class=\"plot\"", p + 1)) ++in_source;
  EXPECT_EQ(in_source, expected);
  // Nothing is loaded from elsewhere (the SVG namespace URI is a name, not a resource).
  for (const char* ext : {"src=\"http", "href=\"http", "url(http", "@import", "src=\"//"})
    EXPECT_EQ(html.find(ext), std::string::npos) << ext;

  CmdResult c = sh("timeout 120 /usr/bin/chromium --headless --no-sandbox --disable-gpu --disable-background-networking "
             "--disable-component-update --no-first-run --disable-sync --user-data-dir=" + (dir / "chrome").string() +
                 " --dump-dom file://" + (dir / "out" / "report.html").string(),
             dir, "chromium");
  ASSERT_EQ(c.code, 0) << c.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(c.out, m, std::regex("id=\"plots-rendered\"[^>]*data-count=\"([0-9]+)\""))) << c.out.substr(0, 2000);
  EXPECT_EQ(std::stoi(m[1]), expected) << "plots laid out with a size by the browser";
  // Thumbnails are inline PNGs.
  EXPECT_NE(c.out.find("src=\"data:image/png;base64,iVBORw0KGgo"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(SweepCli, KilledSweepResumesWithOnlyTheMissingPoints) {
  auto dir = fresh("kill");
  auto file = led_count_sweep(dir, {3, 4, 5, 6, 7, 8});
  auto out = dir / "out";
  pid_t pid = start_sweep(file.string() + " -o " + out.string(), dir);
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(wait_for_points(out, 1)) << slurp(dir / "bg.err");
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the sweep finished before it was killed";
  auto before = point_files(out);
  ASSERT_GE(before.size(), 1u);
  ASSERT_LT(before.size(), 6u);
  std::map<std::string, FileState> kept;
  for (auto& p : before) kept[p.string()] = state_of(p);

  CmdResult r = sweep(file.string() + " -o " + out.string() + " --json", dir, "rerun");
  ASSERT_EQ(r.code, 0) << r.err;
  auto summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["already_done"], int(before.size()));
  EXPECT_EQ(summary["computed"], 6 - int(before.size()));
  EXPECT_EQ(summary["finished"], 6);
  // Finished results were not touched: same bytes, same modification time.
  for (auto& [path, st] : kept) {
    FileState now = state_of(path);
    EXPECT_EQ(now.bytes, st.bytes) << path;
    EXPECT_EQ(now.mtime_ns, st.mtime_ns) << path;
  }
  // Complete, no duplicates, no temporaries left.
  EXPECT_EQ(point_files(out).size(), 6u);
  EXPECT_EQ(temporaries(out), 0);
  auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), 6u);
  std::set<std::string> idx, keys;
  for (auto& row : rows) {
    idx.insert(row["index"]);
    keys.insert(row["key"]);
  }
  EXPECT_EQ(idx, (std::set<std::string>{"0", "1", "2", "3", "4", "5"}));
  EXPECT_EQ(keys.size(), 6u);
  // A third run has nothing to do.
  CmdResult again = sweep(file.string() + " -o " + out.string() + " --json", dir, "again");
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(nlohmann::json::parse(again.out)["computed"], 0);
  std::filesystem::remove_all(dir);
}

TEST(SweepCli, SigintSavesFinishedPointsAndExits130) {
  auto dir = fresh("sigint");
  auto file = led_count_sweep(dir, {3, 4, 5, 6});
  auto out = dir / "out";
  pid_t pid = start_sweep(file.string() + " -o " + out.string(), dir);
  ASSERT_TRUE(wait_for_points(out, 1)) << slurp(dir / "bg.err");
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130) << slurp(dir / "bg.err");
  size_t saved = point_files(out).size();
  EXPECT_GE(saved, 1u);
  EXPECT_LT(saved, 4u);
  EXPECT_EQ(temporaries(out), 0);
  // The report of what finished was written on the way out.
  EXPECT_EQ(read_csv(out / "results.csv").size(), saved);
  CmdResult r = sweep(file.string() + " -o " + out.string() + " --json", dir, "rerun");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["already_done"], int(saved));
  EXPECT_EQ(point_files(out).size(), 4u);
  std::filesystem::remove_all(dir);
}

TEST(SweepCli, ShardsPartitionTheDesign) {
  auto dir = fresh("shards");
  auto out = dir / "out";
  CmdResult a = sweep(kTiny + " -o " + out.string() + " --shard 0/2 --json", dir, "a");
  ASSERT_EQ(a.code, 0) << a.err;
  auto sa = nlohmann::json::parse(a.out);
  EXPECT_EQ(sa["shard_points"], 2);
  EXPECT_EQ(sa["computed"], 2);
  std::set<std::string> first;
  for (auto& row : read_csv(out / "results.csv")) first.insert(row["index"]);
  EXPECT_EQ(first, (std::set<std::string>{"0", "2"}));
  CmdResult b = sweep(kTiny + " -o " + out.string() + " --shard 1/2 --json", dir, "b");
  ASSERT_EQ(b.code, 0) << b.err;
  auto sb = nlohmann::json::parse(b.out);
  EXPECT_EQ(sb["computed"], 2);
  EXPECT_EQ(sb["already_done"], 0);
  EXPECT_EQ(sb["finished"], 4);
  EXPECT_EQ(read_csv(out / "results.csv").size(), 4u);
  CmdResult bad = sweep(kTiny + " -o " + out.string() + " --shard 2/2", dir, "bad");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--shard"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(SweepCli, MpirunSpreadsPointsOverRanksAndGathersTheSameResults) {
  auto dir = fresh("mpi");
  // CI installs OpenMPI: a missing mpirun is a failure, not a skip.
  CmdResult v = sh("mpirun --version", dir, "version");
  ASSERT_EQ(v.code, 0) << "mpirun not available: " << v.err;
  std::string env = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 ";
  // Under sanitizers (make sanitize) the ranks run without LeakSanitizer: Open MPI unloads its
  // components at MPI_Finalize and leaves their allocations behind, reported as leaks from
  // "<unknown module>" that no suppression by library name can match. ASan and UBSan still check
  // both ranks; the single-process sweep tests keep the leak check on the sweep code.
  if (ofl::test::kSanitized) env += "ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 ";
  CmdResult m = sh(env + "mpirun -np 2 --oversubscribe " + std::string(OFL_BINARY) + " sweep " + kTiny + " -o " +
                 (dir / "mpi").string() + " --json",
             dir, "mpirun");
  ASSERT_EQ(m.code, 0) << m.err;
  auto summary = nlohmann::json::parse(m.out);  // only rank 0 prints it
  EXPECT_EQ(summary["ranks"], 2);
  EXPECT_EQ(summary["finished"], 4);
  EXPECT_EQ(summary["computed"], 4);
  std::set<int> ranks;
  std::map<std::string, nlohmann::json> mpi_metrics;
  for (auto& p : point_files(dir / "mpi")) {
    auto j = nlohmann::json::parse(slurp(p));
    ranks.insert(j["rank"].get<int>());
    mpi_metrics[j["key"]] = j["metrics"];
  }
  EXPECT_EQ(ranks, (std::set<int>{0, 1})) << "both ranks rendered points";
  EXPECT_EQ(read_csv(dir / "mpi" / "results.csv").size(), 4u);
  // The same sweep in one process gives the same points with the same numbers.
  CmdResult s = sweep(kTiny + " -o " + (dir / "serial").string() + " --json", dir, "serial");
  ASSERT_EQ(s.code, 0) << s.err;
  auto serial = point_files(dir / "serial");
  ASSERT_EQ(serial.size(), 4u);
  for (auto& p : serial) {
    auto j = nlohmann::json::parse(slurp(p));
    ASSERT_TRUE(mpi_metrics.count(j["key"])) << j["key"];
    EXPECT_EQ(mpi_metrics[j["key"]], j["metrics"]);
  }
  std::filesystem::remove_all(dir);
}

TEST(SweepCli, BadSweepFilesExitWithCode2NamingTheField) {
  auto dir = fresh("bad");
  nlohmann::json j = {{"scene", kSource + "/scenes/oraleye_385.json"},
                      {"camera", kSource + "/scenes/cameras/oraleye.json"},
                      {"parameters", {{{"name", "n"}, {"scene", "/lights/7/count"}, {"values", {3}}}}}};
  std::ofstream(dir / "bad.json") << j.dump();
  CmdResult r = sweep((dir / "bad.json").string() + " -o " + (dir / "out").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("/parameters/0/scene"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "points")) << "nothing rendered for a bad sweep";
  j["parameters"][0] = {{"name", "n"}, {"generator", "led_count"}, {"valeus", {3}}};
  std::ofstream(dir / "bad.json") << j.dump();
  r = sweep((dir / "bad.json").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/parameters/0/valeus"), std::string::npos) << r.err;
  std::filesystem::remove_all(dir);
}

TEST(SweepCli, DryRunListsEveryPointAndWritesNothing) {
  auto dir = fresh("dry");
  CmdResult r = sweep(kTiny + " -o " + (dir / "out").string() + " --dry-run", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  int lines = 0;
  for (size_t p = r.out.find("missing"); p != std::string::npos; p = r.out.find("missing", p + 1)) ++lines;
  EXPECT_EQ(lines, 4) << r.out;
  EXPECT_NE(r.out.find("leds=6 distance_m=0.095"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  std::filesystem::remove_all(dir);
}

TEST(SweepCli, SppWidthHeightOverrideTheFileAndChangeThePointKeys) {
  auto dir = fresh("overrides");
  auto keys = [&](const std::string& extra) {
    CmdResult r = sweep(kTiny + " -o " + (dir / "out").string() + " --dry-run" + extra, dir);
    EXPECT_EQ(r.code, 0) << r.err;
    std::set<std::string> k;
    std::istringstream in(r.out);
    std::string idx, key;
    while (in >> idx >> key)
      if (key.size() == 16) k.insert(key), in.ignore(1 << 20, '\n');
      else in.ignore(1 << 20, '\n');
    return k;
  };
  auto base = keys(""), spp = keys(" --spp 3"), width = keys(" --width 40");
  EXPECT_EQ(base.size(), 4u);
  EXPECT_EQ(spp.size(), 4u);
  EXPECT_EQ(width.size(), 4u);
  for (auto& k : spp) EXPECT_EQ(base.count(k), 0u) << "--spp must change every point's key";
  for (auto& k : width) EXPECT_EQ(base.count(k), 0u) << "--width must change every point's key";
  EXPECT_EQ(keys(" --spp 3"), spp) << "the same overrides give the same keys";
  CmdResult bad = sweep(kTiny + " -o " + (dir / "out").string() + " --dry-run --spp 0", dir);
  EXPECT_EQ(bad.code, 2) << bad.err;
  std::filesystem::remove_all(dir);
}
