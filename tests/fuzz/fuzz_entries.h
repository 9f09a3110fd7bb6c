// libFuzzer entry points for every parser. Each takes the bytes of one input
// file, puts them where the parser expects a file (a private temporary folder) and calls the
// parser itself: no scene building, no rendering, so a harness runs at hundreds to thousands of
// executions per second. An InputError is the expected answer to a bad input and is swallowed;
// any other exception, a crash or a sanitizer report is a finding.
//
// The same entries run in the normal build: tests/test_fuzz_regressions.cpp feeds them the shipped
// files, deterministic mutations of them and every saved finding in tests/fuzz/regressions/<name>/.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ofl::fuzz {

struct Entry {
  const char* name;       // harness name: fuzz_<name>
  const char* extension;  // the file name the parser sees ends with this
  void (*run)(const uint8_t* data, size_t size);
  std::vector<std::string> seeds;  // shipped files (relative to the source folder) that seed the corpus
};

const std::vector<Entry>& entries();
const Entry* find_entry(const std::string& name);
// Calls entry.run and swallows ofl::InputError; returns 0 (libFuzzer's convention).
int run_entry(const Entry& e, const uint8_t* data, size_t size);
// Environment every harness runs in: a small memory limit (OFL_MEMORY_LIMIT_MIB=1024).
void init_fuzz_environment();

}  // namespace ofl::fuzz
