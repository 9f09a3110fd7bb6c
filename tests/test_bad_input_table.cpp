// Walks the bad-input table in docs/bad-inputs.md: every row names an input under
// tests/data/bad_inputs, a command, the exit code and a piece of the message. Each row is run
// through the real CLI; the output must contain the text, hold no raw binary bytes, and the
// output folder must hold no temporary files. A command may be several steps joined by " && "
// (leading NAME=value words set a step's environment; "@truncate", "@flip", "@swap" and "@write"
// steps damage files, such as cache entries a previous step wrote): the last step is the answer.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
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

std::vector<std::string> split(const std::string& s, const std::string& sep) {
  std::vector<std::string> out;
  size_t at = 0;
  for (size_t next; (next = s.find(sep, at)) != std::string::npos; at = next + sep.size()) out.push_back(trim(s.substr(at, next - at)));
  out.push_back(trim(s.substr(at)));
  return out;
}

// The files a glob names (one '*' in the file name at most), sorted.
std::vector<fs::path> glob(const std::string& pattern) {
  fs::path p = pattern;
  std::string name = p.filename().string();
  size_t star = name.find('*');
  if (star == std::string::npos) return {p};
  std::vector<fs::path> out;
  std::error_code ec;
  for (auto& e : fs::directory_iterator(p.parent_path(), ec)) {
    std::string n = e.path().filename().string();
    if (n.size() + 1 >= name.size() && n.rfind(name.substr(0, star), 0) == 0 &&
        n.compare(n.size() - (name.size() - star - 1), std::string::npos, name.substr(star + 1)) == 0)
      out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
void write_file(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }

// A damage step ("@truncate GLOB BYTES", "@flip GLOB OFFSET", "@swap GLOB", "@write GLOB TEXT"):
// applied to every file the glob names ("@swap": exchanges the first two files' bytes). Returns ""
// or what went wrong.
std::string damage(const std::string& step) {
  std::istringstream in(step);
  std::string verb, pattern, arg;
  in >> verb >> pattern;
  std::getline(in, arg);
  arg = trim(arg);
  auto files = glob(pattern);
  if (files.empty() || !fs::exists(files.front())) return step + ": no file matches";
  if (verb == "@swap") {
    if (files.size() < 2) return step + ": needs two files";
    std::string a = read_file(files[0]), b = read_file(files[1]);
    write_file(files[0], b);
    write_file(files[1], a);
    return "";
  }
  for (auto& f : files) {
    std::string bytes = read_file(f);
    if (verb == "@truncate") bytes.resize(std::min(bytes.size(), size_t(std::stoull(arg))));
    else if (verb == "@flip" && std::stoull(arg) < bytes.size()) bytes[std::stoull(arg)] ^= 0x5a;
    else if (verb == "@write") bytes = arg;
    else return step + ": unknown damage or offset past the end";
    write_file(f, bytes);
  }
  return "";
}

// One oralfluor step: leading NAME=value words are its environment.
ofl::test::CliResult run_step(const std::string& step) {
  std::istringstream in(step);
  std::string env, word;
  std::streampos args_at = 0;
  while (in >> word && word.find('=') != std::string::npos && word.find('=') > 0 && word[0] != '-') {
    env += word + " ";
    args_at = in.tellg();
  }
  std::string args = step.substr(size_t(args_at));
  if (env.empty()) return ofl::test::run_cli(args);
  std::string cmd = env + std::string(OFL_BINARY) + " " + args + " 2>&1";
  ofl::test::CliResult r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Runs a row's command: steps joined by " && "; "@..." steps damage files, the others run oralfluor.
// Every step but the last must succeed; the last one's answer is the row's.
ofl::test::CliResult run_row(const std::string& command) {
  auto steps = split(command, " && ");
  for (size_t i = 0; i + 1 < steps.size(); ++i) {
    if (steps[i].rfind("@", 0) == 0) {
      std::string e = damage(steps[i]);
      if (!e.empty()) return {-2, "setup step failed: " + e};
      continue;
    }
    auto r = run_step(steps[i]);
    if (r.exit_code != 0) return {-2, "setup step failed: " + steps[i] + "\n" + r.output};
  }
  return run_step(steps.back());
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
    auto t0 = std::chrono::steady_clock::now();
    auto res = run_row(cmd);
    if (std::getenv("OFL_TEST_VERBOSE"))
      std::printf("%.2f s  line %d: %s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), r.line,
                  r.what.c_str());
    EXPECT_EQ(res.exit_code, r.exit_code) << cmd << "\n" << res.output;
    EXPECT_NE(res.output.find(expect), std::string::npos) << cmd << "\nexpected: " << expect << "\ngot: " << res.output;
    if (r.exit_code != 0) {
      EXPECT_EQ(res.output.find("internal error"), std::string::npos) << res.output;
    }
    if (r.exit_code == 2) {
      // One error line; any other line is oralfluor's own ("warning: ", "sweep: "), never a
      // library's (libpng prints "libpng error: ..." itself).
      int errors = 0;
      std::istringstream lines(res.output);
      for (std::string l; std::getline(lines, l);) {
        errors += l.rfind("error: ", 0) == 0;
        size_t colon = l.find(": ");
        bool own = colon != std::string::npos && colon > 0 &&
                   std::all_of(l.begin(), l.begin() + long(colon), [](char c) { return (c >= 'a' && c <= 'z') || c == '-' || c == '_'; });
        EXPECT_TRUE(own || l.rfind("sweep[rank ", 0) == 0) << "not one of oralfluor's lines: " << l;
      }
      EXPECT_EQ(errors, 1) << res.output;
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
