// The point store: atomic writes leave no temporary behind, a file is only accepted under its own
// key, and temporaries of dead writers on this host are cleaned while live or foreign ones stay.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <fstream>

#include "renderer/sweep/store/sweep_store.h"
#include "renderer/sweep/sweep_point.h"

using namespace ofl;

namespace {
std::filesystem::path fresh(const std::string& name) {
  auto p = std::filesystem::temp_directory_path() / ("ofl_sweep_store_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}
std::string host() {
  char h[256] = "";
  ::gethostname(h, sizeof h - 1);
  std::string s = h;
  for (char& c : s)
    if (c == '.' || c == '/') c = '_';
  return s;
}
std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
}  // namespace

TEST(SweepStore, AtomicWriteReplacesWholeFilesAndLeavesNoTemporary) {
  auto dir = fresh("atomic");
  write_file_atomic(dir / "a.txt", "first");
  write_file_atomic(dir / "a.txt", "second, longer");
  EXPECT_EQ(slurp(dir / "a.txt"), "second, longer");
  int files = 0;
  for (auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
  std::filesystem::remove_all(dir);
}

TEST(SweepStore, LoadsOnlyCompleteFilesUnderTheirOwnKey) {
  auto dir = fresh("keys");
  PointStore st(dir);
  nlohmann::ordered_json r = {{"key", "00000000000000aa"}, {"index", 3}};
  st.save("00000000000000aa", r);
  ASSERT_TRUE(st.has("00000000000000aa"));
  EXPECT_EQ((*st.load("00000000000000aa"))["index"], 3);
  // A file whose content names another key, or that does not parse, is not a result.
  std::ofstream(st.file_for("00000000000000bb")) << nlohmann::json({{"key", "00000000000000cc"}}).dump();
  std::ofstream(st.file_for("00000000000000dd")) << "{\"key\": \"00000000000000dd\", ";
  EXPECT_FALSE(st.has("00000000000000bb"));
  EXPECT_FALSE(st.has("00000000000000dd"));
  EXPECT_FALSE(st.has("00000000000000ee"));
  std::filesystem::remove_all(dir);
}

TEST(SweepStore, RemovesOnlyTemporariesOfDeadProcessesOnThisHost) {
  auto dir = fresh("tmp");
  PointStore st(dir);
  // A pid that surely is dead: a child that exited and was reaped.
  pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  auto dead = st.dir() / (".k1.json." + host() + "." + std::to_string(child) + ".tmp");
  auto live = st.dir() / (".k2.json." + host() + "." + std::to_string(::getpid()) + ".tmp");
  auto other = st.dir() / (".k3.json.some-other-host." + std::to_string(child) + ".tmp");
  for (auto& p : {dead, live, other}) std::ofstream(p) << "partial";
  EXPECT_EQ(st.remove_stale_temporaries(), 1);
  EXPECT_FALSE(std::filesystem::exists(dead));
  EXPECT_TRUE(std::filesystem::exists(live));
  EXPECT_TRUE(std::filesystem::exists(other));
  EXPECT_TRUE(st.keys().empty());  // temporaries are never results
  std::filesystem::remove_all(dir);
}

TEST(SweepStore, Base64RoundTripsEveryByte) {
  std::string bytes;
  for (int i = 0; i < 256; ++i) bytes += char(i);
  for (size_t n : {0u, 1u, 2u, 3u, 4u, 255u, 256u}) {
    std::string part = bytes.substr(0, n);
    std::string text = base64_encode(part);
    EXPECT_EQ(text.size() % 4, 0u);
    EXPECT_EQ(base64_decode(text), part) << n;
  }
  EXPECT_EQ(base64_encode("Man"), "TWFu");  // RFC 4648 examples
  EXPECT_EQ(base64_encode("Ma"), "TWE=");
  EXPECT_EQ(base64_encode("M"), "TQ==");
}
