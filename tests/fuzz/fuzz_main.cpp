// One libFuzzer harness per parser: built with -DOFL_FUZZ_ENTRY="<name>" (CMake option OFL_FUZZ,
// clang only). The entry itself lives in fuzz_entries.cpp, shared with the normal test build.
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "tests/fuzz/fuzz_entries.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ofl::fuzz::init_fuzz_environment();
  if (!ofl::fuzz::find_entry(OFL_FUZZ_ENTRY)) {
    std::fprintf(stderr, "no fuzz entry %s\n", OFL_FUZZ_ENTRY);
    std::abort();
  }
  // OFL_FUZZ_SEED_DIR=<dir>: copy this entry's shipped seed files into <dir> and exit (run.sh
  // builds the corpora this way, so the seed lists live in one place).
  if (const char* dir = std::getenv("OFL_FUZZ_SEED_DIR")) {
    namespace fs = std::filesystem;
    fs::create_directories(dir);
    for (const auto& s : ofl::fuzz::find_entry(OFL_FUZZ_ENTRY)->seeds)
      fs::copy_file(fs::path(OFL_SOURCE_DIR) / s, fs::path(dir) / fs::path(s).filename(), fs::copy_options::overwrite_existing);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const ofl::fuzz::Entry* e = ofl::fuzz::find_entry(OFL_FUZZ_ENTRY);
  return ofl::fuzz::run_entry(*e, data, size);
}
