// The memory a request may ask for. Sizes that come from input files or options (image headers,
// resolutions, band counts, mesh and grid sizes) are checked against this limit before anything is
// allocated, so an impossible request is an input error saying what it needs, not std::bad_alloc
// after minutes of swapping.
//
// The limit is the machine's physical memory (sysconf), lowered by RLIMIT_AS when one is set;
// the environment variable OFL_MEMORY_LIMIT_MIB replaces it (tests use it to stay small).
#pragma once
#include <cstdint>
#include <string>

namespace ofl {

// The limit in bytes.
uint64_t memory_limit_bytes();
// Where the limit comes from, e.g. "physical memory" or "OFL_MEMORY_LIMIT_MIB".
std::string memory_limit_source();
// "3.2 GiB", "640 KiB": bytes in a readable unit.
std::string format_bytes(double bytes);
// Throws InputError(file, field, "<what> needs N GiB, limit M GiB (<source>)") when `bytes`
// (computed in double so that nothing overflows) exceeds the limit or is not finite.
void check_memory(const std::string& file, const std::string& field, double bytes, const std::string& what);

}  // namespace ofl
