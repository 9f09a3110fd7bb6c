// The fuzz harnesses' entries (tests/fuzz/fuzz_entries.cpp) in the normal build: every parser is
// fed its shipped seed files, deterministic mutations of them (truncations, overwritten bytes, a
// number that overflows a double) and every saved finding under tests/fuzz/regressions/<entry>/.
// A bad input must end as an InputError; any other exception fails the test. Crashes would end
// the test binary, which ctest reports as a failure too.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "tests/fuzz/fuzz_entries.h"

namespace fs = std::filesystem;

namespace {

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

struct Case {
  std::string what, bytes;
};

// A fixed set of damaged variants of `s`.
std::vector<Case> mutations(const std::string& name, const std::string& s) {
  std::vector<Case> out{{name, s}};
  const size_t n = s.size();
  for (size_t cut : {size_t(0), size_t(1), n / 3, n / 2, n > 0 ? n - 1 : 0})
    if (cut < n) out.push_back({name + " cut to " + std::to_string(cut) + " bytes", s.substr(0, cut)});
  const char repl[] = {'\xff', '\0', '9', '-', '"', '['};
  for (int k = 0; k < 8 && n > 0; ++k) {
    size_t at = (n * (2 * k + 1)) / 16;
    std::string m = s;
    m[at] = repl[k % 6];
    out.push_back({name + " byte " + std::to_string(at) + " replaced", m});
  }
  // A number no double can hold, where the first number of the file starts.
  if (size_t d = s.find_first_of("0123456789"); d != std::string::npos)
    out.push_back({name + " with 1e999", s.substr(0, d) + "1e999" + s.substr(d + 1)});
  return out;
}

}  // namespace

TEST(FuzzRegressions, EveryEntryAnswersSeedsMutationsAndFindingsWithInputErrorsOnly) {
  ofl::fuzz::init_fuzz_environment();
  const fs::path src = OFL_SOURCE_DIR;
  ASSERT_GE(ofl::fuzz::entries().size(), 14u);
  int runs = 0;
  for (const auto& e : ofl::fuzz::entries()) {
    std::vector<Case> cases;
    for (const auto& seed : e.seeds) {
      ASSERT_TRUE(fs::is_regular_file(src / seed)) << e.name << ": missing seed " << seed;
      auto m = mutations(seed, read_bytes(src / seed));
      cases.insert(cases.end(), m.begin(), m.end());
    }
    std::error_code ec;
    for (auto& f : fs::directory_iterator(src / "tests" / "fuzz" / "regressions" / e.name, ec))
      cases.push_back({f.path().string(), read_bytes(f.path())});
    EXPECT_FALSE(cases.empty()) << e.name << " has no seeds";
    for (const auto& c : cases) {
      ++runs;
      try {
        ofl::fuzz::run_entry(e, reinterpret_cast<const uint8_t*>(c.bytes.data()), c.bytes.size());
      } catch (const std::exception& x) {
        ADD_FAILURE() << "fuzz_" << e.name << " on " << c.what << ": not an input error: " << x.what();
      }
    }
  }
  std::printf("fuzz entries: %d inputs, every one answered\n", runs);
}
