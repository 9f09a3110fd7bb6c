#include "renderer/image/exr_header.h"

#include <cstring>
#include <fstream>
#include <string>

#include "renderer/core/error.h"
#include "renderer/core/memory_limit.h"

namespace ofl {

namespace {
// Bytes of a value of the fixed-size attribute types OpenEXR knows (-1: variable or unknown).
int fixed_size(const std::string& type) {
  static const std::pair<const char*, int> sizes[] = {
      {"box2i", 16}, {"box2f", 16}, {"compression", 1}, {"lineOrder", 1}, {"envmap", 1}, {"deepImageState", 1},
      {"float", 4},  {"int", 4},    {"double", 8},      {"rational", 8},  {"timecode", 8}, {"v2i", 8},
      {"v2f", 8},    {"v2d", 16},   {"v3i", 12},        {"v3f", 12},      {"v3d", 24},    {"m33f", 36},
      {"m33d", 72},  {"m44f", 64},  {"m44d", 128},      {"chromaticities", 32}, {"keycode", 28}, {"tiledesc", 9}};
  for (auto& [name, size] : sizes)
    if (type == name) return size;
  return -1;
}
}  // namespace

ExrHeaderInfo check_exr_header(const std::filesystem::path& file) {
  ExrHeaderInfo info;
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(file, ec);
  if (ec) return info;  // the reader reports a missing file in its own words
  std::ifstream in(file, std::ios::binary);
  unsigned char head[8];
  if (!in.read(reinterpret_cast<char*>(head), 8) || !(head[0] == 0x76 && head[1] == 0x2f && head[2] == 0x31 && head[3] == 0x01))
    return info;
  info.is_exr = true;
  const std::string f = file.string();
  const uint32_t flags = uint32_t(head[5]) << 8 | uint32_t(head[6]) << 16 | uint32_t(head[7]) << 24;
  const bool multipart = flags & 0x1000;
  const size_t max_name = (flags & 0x400) ? 255 : 31;
  uint64_t pos = 8;

  auto read_name = [&](const char* what) {
    std::string s;
    for (;;) {
      int c = in.get();
      if (c == EOF) throw InputError(f, "header", std::string("truncated EXR header (inside an attribute ") + what + ")");
      ++pos;
      if (c == 0) return s;
      s += char(c);
      if (s.size() > max_name) throw InputError(f, "header", std::string("attribute ") + what + " \"" + printable(s) + "\" is too long");
    }
  };
  auto read_i32 = [&]() {
    unsigned char b[4];
    if (!in.read(reinterpret_cast<char*>(b), 4)) throw InputError(f, "header", "truncated EXR header");
    pos += 4;
    return int32_t(uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24);
  };

  for (int part = 0;; ++part) {
    bool first_attribute = true;
    for (;;) {
      std::string name = read_name("name");
      if (name.empty()) break;
      first_attribute = false;
      std::string type = read_name("type");
      const std::string field = "header attribute \"" + printable(name) + "\"";
      int32_t n = read_i32();
      if (n < 0 || uint64_t(n) > size - pos)
        throw InputError(f, field, "claims " + std::to_string(n) + " bytes but only " + std::to_string(size - pos) +
                                       " bytes of the file are left");
      if ((type == "string" || type == "stringvector") && n > kMaxExrStringAttribute)
        throw InputError(f, field, "string of " + format_bytes(double(n)) + " exceeds the limit of " +
                                       format_bytes(double(kMaxExrStringAttribute)));
      // OpenEXR reads a value of a fixed-size type by its type, not by the size field: a size
      // that disagrees makes its walk and this one part ways (found by fuzz_spectral_exr: a
      // lineOrder of "65 bytes" hid a 2 GB string from this check). Such sizes are errors.
      if (int expected = fixed_size(type); expected >= 0 && n != expected)
        throw InputError(f, field, "a " + printable(type) + " value has " + std::to_string(expected) + " bytes, the header says " +
                                       std::to_string(n));
      if (part == 0 && name == "dataWindow" && type == "box2i" && n == 16) {
        int64_t x0 = read_i32(), y0 = read_i32(), x1 = read_i32(), y1 = read_i32();
        if (x1 < x0 || y1 < y0) throw InputError(f, field, "empty or inverted data window");
        info.width = x1 - x0 + 1;
        info.height = y1 - y0 + 1;
      } else if (part == 0 && name == "channels" && type == "chlist") {
        // name\0 + 16 bytes per channel, ended by an empty name.
        uint64_t end = pos + uint64_t(n);
        while (pos < end) {
          int c = in.get();
          ++pos;
          if (c == 0) break;
          std::string cname(1, char(c));
          for (int k; (k = in.get()) != 0;) {
            if (k == EOF || pos >= end) throw InputError(f, field, "truncated channel list");
            ++pos;
            cname += char(k);
          }
          ++pos;
          in.seekg(16, std::ios::cur);
          pos += 16;
          ++info.channels;
        }
        if (pos != end) throw InputError(f, field, "channel list does not match its size");
        in.seekg(std::streamoff(pos));
      } else if (type == "preview" || type == "stringvector") {
        // Sizes inside the value: a preview's width x height x 4 bytes, a string vector's lengths.
        const uint64_t end = pos + uint64_t(n);
        if (type == "preview") {
          if (n < 8) throw InputError(f, field, "preview shorter than its dimensions");
          uint64_t w = uint32_t(read_i32()), h = uint32_t(read_i32());
          if (w * h * 4 != end - pos) throw InputError(f, field, "preview of " + std::to_string(w) + "x" + std::to_string(h) + " pixels does not match its size");
        } else {
          while (pos < end) {
            if (end - pos < 4) throw InputError(f, field, "truncated string vector");
            int32_t len = read_i32();
            if (len < 0 || uint64_t(len) > end - pos) throw InputError(f, field, "string vector entry runs past the attribute");
            pos += uint64_t(len);
            in.seekg(std::streamoff(pos));
          }
        }
        pos = end;
        in.seekg(std::streamoff(pos));
      } else {
        pos += uint64_t(n);
        in.seekg(std::streamoff(pos));
      }
      if (!in) throw InputError(f, field, "truncated EXR header");
    }
    if (!multipart) break;
    if (first_attribute) break;  // an empty header ends the list of parts
    if (part > 10000) throw InputError(f, "header", "more than 10000 parts");
  }
  if (info.width > 0)
    check_memory(f, "dataWindow",
                 double(info.width) * double(info.height) * double(std::max(info.channels, 1)) * sizeof(float),
                 "an image of " + std::to_string(info.width) + "x" + std::to_string(info.height) + " pixels with " +
                     std::to_string(info.channels) + " channels");
  return info;
}

}  // namespace ofl
