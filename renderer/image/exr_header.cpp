#include "renderer/image/exr_header.h"

#include <cstring>
#include <fstream>
#include <string>

#include "renderer/core/errors/error.h"
#include "renderer/core/process/memory_limit.h"

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

namespace {

// Scan lines per chunk of each compression (OpenEXR file layout); -1: unknown.
int lines_per_chunk(int compression) {
  switch (compression) {
    case 0: case 1: case 2: return 1;    // none, RLE, ZIPS
    case 3: case 5: return 16;           // ZIP, PXR24
    case 4: case 6: case 7: case 8: return 32;  // PIZ, B44, B44A, DWAA
    case 9: return 256;                  // DWAB
    default: return -1;
  }
}

// A single-part scanline file: after the header, one 64-bit offset per chunk, and at each chunk its
// first line (int32) and its data size (int32). OpenEXR allocates a chunk's stated size before
// reading it (found by fuzz_spectral_exr: 8 kB files whose chunks claimed 1.6-1.8 GB), so every
// chunk the table points to inside the file, and the chunks in file order after the table (which
// OpenEXR walks when the table is damaged), must fit in what is left of the file.
void check_scanline_chunks(std::ifstream& in, const std::string& f, uint64_t size, uint64_t table, int64_t height,
                           int compression) {
  const int lines = lines_per_chunk(compression);
  if (lines < 0) return;  // OpenEXR names an unknown compression itself
  const int64_t chunks = (height + lines - 1) / lines;
  if (uint64_t(chunks) > (size - std::min(size, table)) / 8)
    throw InputError(f, "line offset table", std::to_string(chunks) + " chunks of " + std::to_string(lines) +
                                                  " lines need a table of " + std::to_string(chunks * 8) + " bytes but only " +
                                                  std::to_string(size - std::min(size, table)) + " bytes of the file are left");
  auto chunk_fits = [&](uint64_t at, int64_t k) {
    unsigned char b[8];
    in.clear();
    in.seekg(std::streamoff(at));
    if (!in.read(reinterpret_cast<char*>(b), 8)) return;  // cut short: OpenEXR says so
    const int32_t n = int32_t(uint32_t(b[4]) | uint32_t(b[5]) << 8 | uint32_t(b[6]) << 16 | uint32_t(b[7]) << 24);
    if (n < 0 || uint64_t(n) > size - at - 8)
      throw InputError(f, "chunk " + std::to_string(k), "claims " + std::to_string(n) + " bytes of pixel data but only " +
                                                            std::to_string(size - at - 8) + " bytes of the file are left");
  };
  const uint64_t first = table + uint64_t(chunks) * 8;
  bool damaged = false;
  for (int64_t k = 0; k < chunks; ++k) {
    unsigned char b[8];
    in.clear();
    in.seekg(std::streamoff(table + uint64_t(k) * 8));
    if (!in.read(reinterpret_cast<char*>(b), 8)) return;
    uint64_t at = 0;
    for (int i = 7; i >= 0; --i) at = at << 8 | b[i];
    if (at >= first && size >= 8 && at <= size - 8) chunk_fits(at, k);
    else damaged = true;
  }
  if (!damaged) return;
  // The chunks in file order, as OpenEXR reads them when it rebuilds a damaged table.
  uint64_t at = first;
  for (int64_t k = 0; k < chunks && at + 8 <= size; ++k) {
    chunk_fits(at, k);
    unsigned char b[8];
    in.clear();
    in.seekg(std::streamoff(at));
    if (!in.read(reinterpret_cast<char*>(b), 8)) return;
    at += 8 + uint64_t(uint32_t(b[4]) | uint32_t(b[5]) << 8 | uint32_t(b[6]) << 16 | uint32_t(b[7]) << 24);
  }
}

// The header's bytes, read in order: `pos` is where the next read starts.
struct HeaderReader {
  std::ifstream& in;
  const std::string& f;
  uint64_t size = 0, pos = 8;
  size_t max_name = 31;

  std::string name(const char* what) {
    std::string s;
    for (;;) {
      int c = in.get();
      if (c == EOF) throw InputError(f, "header", std::string("truncated EXR header (inside an attribute ") + what + ")");
      ++pos;
      if (c == 0) return s;
      s += char(c);
      if (s.size() > max_name) throw InputError(f, "header", std::string("attribute ") + what + " \"" + printable(s) + "\" is too long");
    }
  }
  int32_t i32() {
    unsigned char b[4];
    if (!in.read(reinterpret_cast<char*>(b), 4)) throw InputError(f, "header", "truncated EXR header");
    pos += 4;
    return int32_t(uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24);
  }
  void skip_to(uint64_t at) {
    pos = at;
    in.seekg(std::streamoff(pos));
  }
};

// A channel list of n bytes: name\0 + 16 bytes per channel, ended by an empty name.
void read_channel_list(HeaderReader& r, int32_t n, const std::string& field, ExrHeaderInfo& info) {
  uint64_t end = r.pos + uint64_t(n);
  while (r.pos < end) {
    int c = r.in.get();
    ++r.pos;
    if (c == 0) break;
    std::string cname(1, char(c));
    for (int k; (k = r.in.get()) != 0;) {
      if (k == EOF || r.pos >= end) throw InputError(r.f, field, "truncated channel list");
      ++r.pos;
      cname += char(k);
    }
    ++r.pos;
    r.in.seekg(16, std::ios::cur);
    r.pos += 16;
    ++info.channels;
  }
  if (r.pos != end) throw InputError(r.f, field, "channel list does not match its size");
  r.in.seekg(std::streamoff(r.pos));
}

// The sizes inside a preview (width x height x 4 bytes) or a string vector (its strings' lengths)
// against the attribute's n bytes.
void check_inner_sizes(HeaderReader& r, const std::string& type, int32_t n, const std::string& field) {
  const uint64_t end = r.pos + uint64_t(n);
  if (type == "preview") {
    if (n < 8) throw InputError(r.f, field, "preview shorter than its dimensions");
    uint64_t w = uint32_t(r.i32()), h = uint32_t(r.i32());
    if (w * h * 4 != end - r.pos) throw InputError(r.f, field, "preview of " + std::to_string(w) + "x" + std::to_string(h) + " pixels does not match its size");
  } else {
    while (r.pos < end) {
      if (end - r.pos < 4) throw InputError(r.f, field, "truncated string vector");
      int32_t len = r.i32();
      if (len < 0 || uint64_t(len) > end - r.pos) throw InputError(r.f, field, "string vector entry runs past the attribute");
      r.skip_to(r.pos + uint64_t(len));
    }
  }
  r.skip_to(end);
}

// One attribute of part `part`; false at the empty name that ends the part's header.
bool read_attribute(HeaderReader& r, int part, ExrHeaderInfo& info, int& compression) {
  std::string name = r.name("name");
  if (name.empty()) return false;
  std::string type = r.name("type");
  const std::string field = "header attribute \"" + printable(name) + "\"";
  int32_t n = r.i32();
  if (n < 0 || uint64_t(n) > r.size - r.pos)
    throw InputError(r.f, field, "claims " + std::to_string(n) + " bytes but only " + std::to_string(r.size - r.pos) +
                                     " bytes of the file are left");
  if ((type == "string" || type == "stringvector") && n > kMaxExrStringAttribute)
    throw InputError(r.f, field, "string of " + format_bytes(double(n)) + " exceeds the limit of " +
                                     format_bytes(double(kMaxExrStringAttribute)));
  // OpenEXR reads a value of a fixed-size type by its type, not by the size field: a size
  // that disagrees makes its walk and this one part ways (found by fuzz_spectral_exr: a
  // lineOrder of "65 bytes" hid a 2 GB string from this check). Such sizes are errors.
  if (int expected = fixed_size(type); expected >= 0 && n != expected)
    throw InputError(r.f, field, "a " + printable(type) + " value has " + std::to_string(expected) + " bytes, the header says " +
                                     std::to_string(n));
  if (part == 0 && name == "dataWindow" && type == "box2i" && n == 16) {
    int64_t x0 = r.i32(), y0 = r.i32(), x1 = r.i32(), y1 = r.i32();
    if (x1 < x0 || y1 < y0) throw InputError(r.f, field, "empty or inverted data window");
    info.width = x1 - x0 + 1;
    info.height = y1 - y0 + 1;
  } else if (part == 0 && name == "channels" && type == "chlist") {
    read_channel_list(r, n, field, info);
  } else if (part == 0 && name == "compression" && type == "compression" && n == 1) {
    int c = r.in.get();
    ++r.pos;
    if (c == EOF) throw InputError(r.f, field, "truncated EXR header");
    compression = c;
  } else if (type == "preview" || type == "stringvector") {
    check_inner_sizes(r, type, n, field);
  } else {
    r.skip_to(r.pos + uint64_t(n));
  }
  if (!r.in) throw InputError(r.f, field, "truncated EXR header");
  return true;
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
  HeaderReader r{in, f};
  r.size = size;
  r.max_name = (flags & 0x400) ? 255 : 31;
  int compression = -1;
  for (int part = 0;; ++part) {
    bool first_attribute = true;
    while (read_attribute(r, part, info, compression)) first_attribute = false;
    if (!multipart) break;
    if (first_attribute) break;  // an empty header ends the list of parts
    if (part > 10000) throw InputError(f, "header", "more than 10000 parts");
  }
  // OpenEXR starts from a default header (64 x 64 pixels, ZIP) and overwrites what the file has.
  if (!multipart && !(flags & 0x200) && !(flags & 0x800))  // single-part scanline, not tiled, not deep
    check_scanline_chunks(in, f, size, r.pos, info.height > 0 ? info.height : 64, compression >= 0 ? compression : 3);
  if (info.width > 0)
    check_memory(f, "dataWindow",
                 double(info.width) * double(info.height) * double(std::max(info.channels, 1)) * sizeof(float),
                 "an image of " + std::to_string(info.width) + "x" + std::to_string(info.height) + " pixels with " +
                     std::to_string(info.channels) + " channels");
  return info;
}

}  // namespace ofl
