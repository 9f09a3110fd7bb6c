#include "renderer/core/process/memory_limit.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "renderer/core/errors/error.h"

namespace ofl {
namespace {

struct Limit {
  uint64_t bytes;
  std::string source;
};

Limit current_limit() {
  if (const char* env = std::getenv("OFL_MEMORY_LIMIT_MIB"); env && *env) {
    char* end = nullptr;
    double mib = std::strtod(env, &end);
    if (end != env && *end == '\0' && mib > 0 && mib < 1e12)
      return {uint64_t(mib * 1024.0 * 1024.0), "OFL_MEMORY_LIMIT_MIB"};
  }
  long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  Limit l{pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : (uint64_t(8) << 30), "physical memory"};
  struct rlimit rl;
  if (::getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY && uint64_t(rl.rlim_cur) < l.bytes)
    l = {uint64_t(rl.rlim_cur), "address-space limit (ulimit -v)"};
  return l;
}

}  // namespace

uint64_t memory_limit_bytes() { return current_limit().bytes; }
std::string memory_limit_source() { return current_limit().source; }

std::string format_bytes(double bytes) {
  const char* unit[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  int u = 0;
  while (bytes >= 1024.0 && u < 6) { bytes /= 1024.0; ++u; }
  char buf[64];
  if (!std::isfinite(bytes)) return "an unbounded amount";
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.1f %s", bytes, unit[u]);
  return buf;
}

void check_memory(const std::string& file, const std::string& field, double bytes, const std::string& what) {
  Limit l = current_limit();
  if (std::isfinite(bytes) && bytes >= 0 && bytes <= double(l.bytes)) return;
  throw InputError(file, field, what + " needs " + format_bytes(bytes) + ", limit " + format_bytes(double(l.bytes)) + " (" + l.source + ")");
}

}  // namespace ofl
