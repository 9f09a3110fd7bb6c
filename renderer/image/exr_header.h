// A bounds check of an OpenEXR file's headers before OpenEXR (or OpenImageIO) reads it. The
// libraries trust the sizes in the header: an attribute that claims 2 GB, or a data window of
// 10^10 pixels, makes them allocate that much before noticing the file is 10 kB. This walks the
// attribute list itself (magic, version, then name/type/size/value until an empty name), checks
// every size against what is left of the file and string attributes against a fixed limit, and
// checks the pixel memory of the first part's data window against the memory limit.
#pragma once
#include <cstdint>
#include <filesystem>

namespace ofl {

// The largest string attribute accepted (16 MiB; the JSON this project stores is a few kB).
inline constexpr int64_t kMaxExrStringAttribute = int64_t(16) << 20;

struct ExrHeaderInfo {
  bool is_exr = false;  // false: not an OpenEXR file (no magic number); nothing was checked
  int64_t width = 0, height = 0;
  int channels = 0;
};

// Throws InputError naming the file and the attribute for a header that does not fit the file,
// an oversized string attribute, or a data window whose float pixels exceed memory_limit_bytes().
ExrHeaderInfo check_exr_header(const std::filesystem::path& file);

}  // namespace ofl
