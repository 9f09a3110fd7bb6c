// Writing onto a full or impossible destination (docs/bad-inputs.md, "Output files"): every command
// that writes files is run (a) with its output under a path whose parent is a regular file, (b) on a
// small tmpfs (when this process may mount one) filled so that the disk runs out inside each of the
// command's files in turn - the fill levels come from a reference run on the normal disk: its files
// in the order they were written, a level one page short of holding each file and everything before
// it - and (c) everywhere, under a file-size limit (RLIMIT_FSIZE) set just below each file's size,
// which makes writes fail the same way without mounting. Below the room the whole output needs,
// every run must exit 2 with one line naming a file on that destination; a run that exits 0 must
// have written every file; and whatever the exit code, every file under its final name must be
// complete (the reference run's bytes where a repeated reference run gives the same bytes; else a
// JSON file that parses, or a text with the reference's line count and final newline) and no
// temporary may be left. Also: identical camera runs give identical bytes (no wall-clock DateTime in
// raw.tiff or electrons.exr).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/cli_runner.h"

namespace fs = std::filesystem;

namespace {

const fs::path kSrc = OFL_SOURCE_DIR;
const fs::path kData = kSrc / "tests" / "data" / "bad_inputs";

struct Command {
  std::string name;
  std::function<std::string(const fs::path& out)> args;  // output folder -> command line
};

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Inputs shared by the commands: a small render, its camera run and ISETCam export, a one-point
// sweep, all on the normal disk.
struct Prepared {
  fs::path dir, radiance, mat, raw, sweep;
};

const Prepared& prepared() {
  static Prepared p = [] {
    Prepared q;
    q.dir = fs::temp_directory_path() / ("ofl_full_device_inputs_" + std::to_string(::getpid()));
    fs::remove_all(q.dir);
    fs::create_directories(q.dir);
    auto r = ofl::test::run_cli("render " + (kData / "gltf_ok.json").string() + " -o " + (q.dir / "r").string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    q.radiance = q.dir / "r" / "radiance.exr";
    q.mat = q.dir / "scene.mat";
    auto e = ofl::test::run_cli("export-iset " + q.radiance.string() + " -o " + q.mat.string());
    EXPECT_EQ(e.exit_code, 0) << e.output;
    auto c = ofl::test::run_cli("camera " + q.radiance.string() + " --camera " + (kSrc / "scenes/cameras/plain_rgb.json").string() +
                                " -o " + (q.dir / "c").string());
    EXPECT_EQ(c.exit_code, 0) << c.output;
    q.raw = q.dir / "c" / "raw.tiff";
    nlohmann::json sw = nlohmann::json::parse(read_bytes(kSrc / "scenes/sweeps/tiny.json"));
    sw["scene"] = (kSrc / "scenes/lesion_385.json").string();
    sw["camera"] = (kSrc / "scenes/cameras/oraleye.json").string();
    for (auto& roi : sw["rois"])
      if (roi.contains("texture")) roi["texture"] = (kSrc / "assets/textures/tongue_lesion.png").string();
    sw["parameters"][0]["values"] = {3};
    sw["parameters"][1]["values"] = {0.08};
    q.sweep = q.dir / "one_point.json";
    std::ofstream(q.sweep) << sw.dump(1);
    return q;
  }();
  return p;
}

std::vector<Command> commands() {
  const Prepared& p = prepared();
  const std::string cam = (kSrc / "scenes" / "cameras" / "plain_rgb.json").string();
  return {
      {"render", [cam](const fs::path& o) {
         return "render " + (kData / "gltf_ok.json").string() + " --camera " + cam + " -o " + o.string();
       }},
      {"camera", [&p, cam](const fs::path& o) { return "camera " + p.radiance.string() + " --camera " + cam + " -o " + o.string(); }},
      {"chroma", [&p](const fs::path& o) { return "chroma " + p.raw.string() + " -o " + o.string(); }},
      {"export-iset", [&p](const fs::path& o) { return "export-iset " + p.radiance.string() + " -o " + (o / "scene.mat").string(); }},
      {"import-iset", [&p](const fs::path& o) { return "import-iset " + p.mat.string() + " -o " + (o / "radiance.exr").string(); }},
      {"mesh texture", [](const fs::path& o) {
         return "mesh texture " + (kSrc / "assets" / "meshes" / "tongue.glb").string() + " --size 64 -o " + o.string();
       }},
      {"mesh mouth", [](const fs::path& o) { return "mesh mouth --segments 16 -o " + (o / "mouth.glb").string(); }},
      {"sweep", [&p](const fs::path& o) { return "--threads 2 sweep " + p.sweep.string() + " -o " + o.string(); }},
      {"diagnose", [](const fs::path& o) {
         return "--threads 2 diagnose " + (kSrc / "assets" / "measurements" / "camera_example").string() + " --model " +
                (kSrc / "scenes" / "diagnose" / "camera_example.json").string() + " --max-causes 1 -o " + o.string();
       }},
  };
}

// `prefix` (shell words before the binary, such as a prlimit) + oralfluor + `args`.
ofl::test::CliResult run_with_prefix(const std::string& prefix, const std::string& args) {
  std::string cmd = "sh -c '" + prefix + " " + std::string(OFL_BINARY) + " " + args + "' 2>&1";
  ofl::test::CliResult r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) r.output.append(buf, n);
  int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// One file of a reference run.
struct RefFile {
  std::string rel, bytes;
  int64_t mtime_ns = 0;
};

// What a command writes: its files in the order they were written (modification time).
struct Reference {
  std::vector<RefFile> files;
  std::vector<RefFile> all;  // every regular file, lock files included (they take room too)
};

std::vector<RefFile> list_files(const fs::path& dir) {
  std::vector<RefFile> out;
  for (auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    RefFile f;
    f.rel = fs::relative(e.path(), dir).string();
    f.bytes = read_bytes(e.path());
    struct stat st {};
    ::stat(e.path().c_str(), &st);
    f.mtime_ns = int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
    out.push_back(f);
  }
  std::sort(out.begin(), out.end(), [](const RefFile& a, const RefFile& b) { return a.mtime_ns < b.mtime_ns; });
  return out;
}

// Each command once on the normal disk (shared by the tests of this file).
const Reference& reference(const Command& c) {
  static std::map<std::string, Reference> refs;
  auto it = refs.find(c.name);
  if (it != refs.end()) return it->second;
  Reference ref;
  std::string folder = c.name;
  std::replace(folder.begin(), folder.end(), ' ', '_');
  fs::path dest = prepared().dir / "reference" / folder / "out";
  fs::remove_all(dest.parent_path());
  fs::create_directories(dest);
  auto r = ofl::test::run_cli(c.args(dest));
  EXPECT_EQ(r.exit_code, 0) << c.name << " on the normal disk\n" << r.output;
  ref.all = list_files(dest);
  for (auto& f : ref.all)
    if (fs::path(f.rel).filename().string()[0] != '.') ref.files.push_back(f);  // not the lock files
  return refs.emplace(c.name, ref).first->second;
}

size_t lines(const std::string& s) { return size_t(std::count(s.begin(), s.end(), '\n')); }

// "" when `bytes` is a complete copy of the reference file, else what is wrong. Images, meshes and
// EXRs are the same bytes in every run; a .mat the same after its header text (which holds the
// creation time); JSON files (with timings) must parse; other text must hold the reference's lines.
std::string incomplete(const RefFile& ref, const std::string& bytes) {
  const std::string ext = fs::path(ref.rel).extension().string();
  if (ext == ".exr" || ext == ".png" || ext == ".tiff" || ext == ".dng" || ext == ".glb")
    return bytes == ref.bytes ? "" : "differs from the reference run's bytes";
  if (ext == ".mat")
    return bytes.size() == ref.bytes.size() && bytes.compare(116, std::string::npos, ref.bytes, 116, std::string::npos) == 0
               ? ""
               : "differs from the reference run's bytes after the header";
  if (ext == ".json") {
    try {
      (void)nlohmann::json::parse(bytes);
      return "";
    } catch (const std::exception&) {
      return "does not parse as JSON";
    }
  }
  if (lines(bytes) != lines(ref.bytes) || bytes.empty() || bytes.back() != ref.bytes.back())
    return "holds " + std::to_string(lines(bytes)) + " lines, the reference " + std::to_string(lines(ref.bytes));
  return "";
}

// Checks one run onto `dest` (the folder the command was told to write into). `must_fail`: the
// destination cannot hold the whole output.
void check_run(const Command& c, const Reference& ref, const fs::path& dest, const ofl::test::CliResult& r,
               const std::string& place, bool must_fail) {
  SCOPED_TRACE(c.name + " on " + place);
  EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  if (must_fail) EXPECT_EQ(r.exit_code, 2) << "the output cannot fit, yet the command succeeded\n" << r.output;
  if (r.exit_code == 0) {
    for (const auto& f : ref.files) EXPECT_TRUE(fs::is_regular_file(dest / f.rel)) << "exit 0 but " << f.rel << " is missing\n" << r.output;
  } else {
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("error: " + dest.parent_path().string()), std::string::npos)
        << "one line naming a file on the destination\n" << r.output;
  }
  for (const auto& f : ref.files)
    if (fs::exists(dest / f.rel)) {
      std::string why = incomplete(f, read_bytes(dest / f.rel));
      EXPECT_EQ(why, "") << f.rel << " is left under its final name but is not complete\n" << r.output;
    }
  auto tmp = ofl::test::temporaries(dest.parent_path());
  EXPECT_TRUE(tmp.empty()) << "left behind: " << (tmp.empty() ? "" : tmp.front()) << "\n" << r.output;
}

// A tmpfs of `kib` KiB at `dir`, unmounted on destruction; ok() is false where mount is not allowed.
class Tmpfs {
 public:
  Tmpfs(const fs::path& dir, int kib) : dir_(dir) {
    fs::create_directories(dir_);
    std::string opts = "size=" + std::to_string(kib) + "k";
    mounted_ = ::mount("tmpfs", dir_.c_str(), "tmpfs", 0, opts.c_str()) == 0;
  }
  ~Tmpfs() {
    if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  bool ok() const { return mounted_; }
  // Fills the file system, then frees `free_pages` pages (4 KiB) again.
  void fill_leaving(int64_t free_pages) const {
    std::error_code ec;
    for (auto& e : fs::directory_iterator(dir_, ec)) fs::remove_all(e.path(), ec);
    int fd = ::open((dir_ / "filler").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0);
    std::vector<char> block(4096, 'x');
    off_t size = 0;
    for (;;) {
      ssize_t n = ::write(fd, block.data(), block.size());
      if (n <= 0) break;
      size += n;
    }
    ASSERT_GE(size, off_t(free_pages) * 4096) << "the tmpfs is too small for this command's output";
    ASSERT_EQ(::ftruncate(fd, size - off_t(free_pages) * 4096), 0);
    ::close(fd);
  }

 private:
  fs::path dir_;
  bool mounted_ = false;
};

int64_t pages(const std::string& bytes) { return int64_t((bytes.size() + 4095) / 4096); }

}  // namespace

TEST(FullDevice, ParentIsAFile) {
  const fs::path base = fs::temp_directory_path() / ("ofl_full_device_file_" + std::to_string(::getpid()));
  fs::remove_all(base);
  fs::create_directories(base);
  std::ofstream(base / "a_file") << "not a folder\n";
  for (const auto& c : commands()) {
    fs::path dest = base / "a_file" / "out";
    auto r = ofl::test::run_cli(c.args(dest));
    SCOPED_TRACE(c.name);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("a_file/out"), std::string::npos) << "the message must name the destination\n" << r.output;
    EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  }
  EXPECT_TRUE(ofl::test::temporaries(base).empty());
  EXPECT_EQ(read_bytes(base / "a_file"), "not a folder\n");
  fs::remove_all(base);
}

// The disk runs out inside each file in turn: the free room is what every file written before it
// takes plus all but one page of it. Below the total every run must fail; with room to spare it
// must succeed.
TEST(FullDevice, NearlyFullTmpfsAtEveryFileOfEveryCommand) {
  const fs::path mnt = fs::temp_directory_path() / ("ofl_full_device_tmpfs_" + std::to_string(::getpid()));
  int64_t most = 0;
  std::vector<std::pair<Command, Reference>> refs;
  for (const auto& c : commands()) {
    refs.emplace_back(c, reference(c));
    int64_t total = 0;
    for (auto& f : refs.back().second.all) total += pages(f.bytes);
    most = std::max(most, total);
  }
  Tmpfs t(mnt, int((most + 64) * 4));
  if (!t.ok()) {
    std::printf("[ SKIPPED  ] the tmpfs part: mounting a tmpfs is not permitted here (needs root or CAP_SYS_ADMIN); "
                "FullDevice.FileSizeLimitAtEveryFileOfEveryCommand still makes every write run out of room\n");
    GTEST_SKIP() << "mount -t tmpfs not permitted";
  }
  int runs = 0;
  for (const auto& [c, ref] : refs) {
    std::vector<std::pair<int64_t, bool>> levels = {{0, true}};  // (free pages, must fail)
    int64_t before = 0;
    for (const auto& f : ref.all) {
      if (pages(f.bytes) > 0 && before + pages(f.bytes) - 1 > levels.back().first)
        levels.push_back({before + pages(f.bytes) - 1, true});
      before += pages(f.bytes);
    }
    levels.push_back({before + 16, false});
    for (auto [free_pages, must_fail] : levels) {
      t.fill_leaving(free_pages);
      fs::path dest = mnt / "out";
      fs::create_directories(dest);
      auto t0 = std::chrono::steady_clock::now();
      auto r = ofl::test::run_cli(c.args(dest));
      if (std::getenv("OFL_TEST_VERBOSE"))
        std::printf("%s at %lld free pages: exit %d after %.1f s\n", c.name.c_str(), (long long)free_pages, r.exit_code,
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      check_run(c, ref, dest, r, "tmpfs with " + std::to_string(free_pages) + " pages free", must_fail);
      if (!must_fail) EXPECT_EQ(r.exit_code, 0) << c.name << " with room to spare\n" << r.output;
      ++runs;
    }
  }
  std::printf("full-device runs on a tmpfs: %d\n", runs);
}

// The same failures without mount: a file-size limit (RLIMIT_FSIZE, set by util-linux prlimit, with
// SIGXFSZ ignored so a write past it fails with EFBIG as on a full device; it binds the in-memory
// files of library writers too). Where no tmpfs can be mounted (an unprivileged CI container) it
// stands in for the tmpfs: one byte below the size of each file larger than every file written
// before it (the first file the limit stops), and 0. Where the tmpfs runs, at 0 only.
TEST(FullDevice, FileSizeLimitAtEveryFileOfEveryCommand) {
  const fs::path base = fs::temp_directory_path() / ("ofl_full_device_fsize_" + std::to_string(::getpid()));
  const bool tmpfs = [] {
    Tmpfs probe(fs::temp_directory_path() / ("ofl_full_device_probe_" + std::to_string(::getpid())), 64);
    return probe.ok();
  }();
  int runs = 0;
  for (const auto& c : commands()) {
    const Reference& ref = reference(c);
    std::vector<size_t> limits = {0};
    size_t largest = 0;
    for (const auto& f : ref.files)
      if (f.bytes.size() > largest && !tmpfs) {
        limits.push_back(f.bytes.size() - 1);
        largest = f.bytes.size();
      }
    for (size_t limit : limits) {
      fs::path dest = base / "run" / "out";
      fs::remove_all(dest.parent_path());
      fs::create_directories(dest);
      auto r = run_with_prefix("trap \"\" XFSZ; exec prlimit --fsize=" + std::to_string(limit), c.args(dest));
      check_run(c, ref, dest, r, "files limited to " + std::to_string(limit) + " bytes", true);
      ++runs;
    }
  }
  fs::remove_all(base);
  std::printf("file-size-limited runs: %d%s\n", runs, tmpfs ? " (the tmpfs test runs every level)" : "");
}

TEST(FullDevice, IdenticalCameraRunsGiveIdenticalBytes) {
  const Prepared& p = prepared();
  const std::string cam = (kSrc / "scenes" / "cameras" / "plain_rgb.json").string();
  fs::path a = p.dir / "cam_a", b = p.dir / "cam_b";
  auto ra = ofl::test::run_cli("camera " + p.radiance.string() + " --camera " + cam + " -o " + a.string());
  ASSERT_EQ(ra.exit_code, 0) << ra.output;
  // Let the wall clock move past a second so a DateTime stamp would differ.
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  auto rb = ofl::test::run_cli("camera " + p.radiance.string() + " --camera " + cam + " -o " + b.string());
  ASSERT_EQ(rb.exit_code, 0) << rb.output;
  for (const char* f : {"raw.tiff", "electrons.exr", "raw.dng", "camera_preview.png"}) {
    std::string x = read_bytes(a / f), y = read_bytes(b / f);
    ASSERT_FALSE(x.empty()) << f;
    EXPECT_TRUE(x == y) << f << " differs between identical runs";
  }
}
