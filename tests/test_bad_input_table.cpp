// Walks the bad-input table in docs/bad-inputs.md: every row names an input under
// tests/data/bad_inputs, a command, the exit code and a piece of the message. Each row is run
// through the real CLI; the output must contain the text, hold no raw binary bytes, and the
// output folder must hold no temporary files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/cli_runner.h"

namespace fs = std::filesystem;

namespace {

struct Row {
  int line = 0;
  std::string what, input, command, expect;
  int exit_code = -1;
};

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.pop_back();
  size_t a = s.find_first_not_of(" \t");
  return a == std::string::npos ? "" : s.substr(a);
}

std::string unquote(std::string s) {
  s = trim(s);
  if (s.size() >= 2 && s.front() == '`' && s.back() == '`') s = s.substr(1, s.size() - 2);
  return s;
}

// Splits "| a | b |" into cells; a '|' inside backticks belongs to the cell.
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool code = false;
  for (size_t i = 1; i < line.size(); ++i) {
    char c = line[i];
    if (c == '`') code = !code;
    if (c == '|' && !code) {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  return out;
}

std::vector<Row> read_table(const fs::path& md) {
  std::ifstream in(md);
  std::vector<Row> rows;
  std::string line;
  bool inside = false, header_seen = false;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.find("<!-- bad-input-table:begin -->") != std::string::npos) { inside = true; continue; }
    if (line.find("<!-- bad-input-table:end -->") != std::string::npos) break;
    if (!inside || line.empty() || line[0] != '|') continue;
    if (!header_seen) { header_seen = true; continue; }  // the header row
    if (line.rfind("|---", 0) == 0) continue;
    auto c = cells(line);
    EXPECT_EQ(c.size(), 5u) << md << ":" << n << ": expected 5 cells: " << line;
    if (c.size() != 5) continue;
    Row r;
    r.line = n;
    r.what = trim(c[0]);
    r.input = unquote(c[1]);
    r.command = unquote(c[2]);
    r.exit_code = std::atoi(trim(c[3]).c_str());
    r.expect = unquote(c[4]);
    rows.push_back(r);
  }
  return rows;
}

std::string substitute(std::string s, const std::string& key, const std::string& value) {
  for (size_t at; (at = s.find(key)) != std::string::npos;) s.replace(at, key.size(), value);
  return s;
}


}  // namespace

TEST(BadInputTable, EveryRowGivesTheDocumentedAnswer) {
  const fs::path src = OFL_SOURCE_DIR;
  const fs::path data = src / "tests" / "data" / "bad_inputs";
  auto rows = read_table(src / "docs" / "bad-inputs.md");
  // The parser must have found the table; a table that silently became empty would pass anything.
  ASSERT_GE(rows.size(), 20u) << "docs/bad-inputs.md: the bad-input table was not found or lost rows";
  ::setenv("OFL_MEMORY_LIMIT_MIB", "4096", 1);
  ::setenv("OFL_NO_PROGRESS", "1", 1);
  const fs::path base = fs::temp_directory_path() / ("ofl_bad_input_table_" + std::to_string(::getpid()));
  int i = 0;
  for (const Row& r : rows) {
    SCOPED_TRACE("docs/bad-inputs.md:" + std::to_string(r.line) + ": " + r.what);
    if (r.input != "-") EXPECT_TRUE(fs::is_regular_file(data / r.input)) << "missing input " << (data / r.input);
    const fs::path out = base / ("row" + std::to_string(++i));
    fs::remove_all(out);
    fs::create_directories(out);
    std::string cmd = substitute(substitute(r.command, "{dir}", data.string()), "{out}", out.string());
    std::string expect = substitute(substitute(r.expect, "{dir}", data.string()), "{out}", out.string());
    auto res = ofl::test::run_cli(cmd);
    EXPECT_EQ(res.exit_code, r.exit_code) << cmd << "\n" << res.output;
    EXPECT_NE(res.output.find(expect), std::string::npos) << cmd << "\nexpected: " << expect << "\ngot: " << res.output;
    if (r.exit_code != 0) {
      EXPECT_EQ(res.output.find("internal error"), std::string::npos) << res.output;
    }
    for (unsigned char c : res.output)
      if (!(c == '\n' || (c >= 0x20 && c < 0x7f))) {
        ADD_FAILURE() << "raw byte 0x" << std::hex << int(c) << " in the output of " << cmd;
        break;
      }
    EXPECT_TRUE(ofl::test::temporaries(out).empty()) << "temporaries left: " << ofl::test::temporaries(out).front();
  }
  EXPECT_TRUE(ofl::test::temporaries(data).empty());
  fs::remove_all(base);
  ::unsetenv("OFL_MEMORY_LIMIT_MIB");
}
