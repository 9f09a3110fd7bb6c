#include "renderer/formats/mat_prescan.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "renderer/core/errors/error.h"
#include "renderer/core/process/memory_limit.h"

namespace ofl {
namespace {

enum : uint32_t {
  miINT8 = 1, miUINT8 = 2, miINT16 = 3, miUINT16 = 4, miINT32 = 5, miUINT32 = 6, miSINGLE = 7, miDOUBLE = 9,
  miINT64 = 12, miUINT64 = 13, miMATRIX = 14, miCOMPRESSED = 15, miUTF8 = 16, miUTF16 = 17, miUTF32 = 18
};
enum : uint32_t { mxCELL = 1, mxSTRUCT = 2, mxCHAR = 4, mxDOUBLE = 6, mxUINT64 = 15 };

size_t mi_size(uint32_t t) {
  switch (t) {
    case miINT8: case miUINT8: case miUTF8: return 1;
    case miINT16: case miUINT16: case miUTF16: return 2;
    case miINT32: case miUINT32: case miSINGLE: case miUTF32: return 4;
    case miDOUBLE: case miINT64: case miUINT64: return 8;
    default: return 0;
  }
}

struct Walker {
  std::string file;
  bool swap = false;

  [[noreturn]] void fail(const std::string& var, const std::string& what) const {
    throw InputError(file, var.empty() ? std::string("data") : "variable \"" + printable(var) + "\"", what + " (damaged file?)");
  }
  uint32_t u32(const uint8_t* q) const {
    uint32_t v;
    std::memcpy(&v, q, 4);
    return swap ? __builtin_bswap32(v) : v;
  }

  // One data element at d[0..len): its type, payload and the bytes it takes with padding.
  struct Element {
    uint32_t type = 0;
    const uint8_t* data = nullptr;
    uint64_t nbytes = 0, total = 0;
  };
  Element element(const uint8_t* d, uint64_t len, const std::string& var) const {
    if (len < 8) fail(var, "truncated data element");
    Element e;
    uint32_t w0 = u32(d);
    if (w0 >> 16) {  // small data element: type and size in one word, payload in the next
      e.type = w0 & 0xffff;
      e.nbytes = w0 >> 16;
      if (e.nbytes > 4) fail(var, "small data element of " + std::to_string(e.nbytes) + " bytes");
      e.data = d + 4;
      e.total = 8;
      return e;
    }
    e.type = w0;
    e.nbytes = u32(d + 4);
    if (e.nbytes > len - 8) fail(var, "element of " + std::to_string(e.nbytes) + " bytes runs past its container (" +
                                           std::to_string(len - 8) + " bytes left)");
    e.data = d + 8;
    e.total = std::min<uint64_t>(len, 8 + ((e.nbytes + 7) / 8) * 8);
    return e;
  }

  // The body of a miMATRIX element.
  void matrix(const uint8_t* d, uint64_t len, int depth, const std::string& outer) const {
    if (len == 0) return;  // an empty matrix
    if (depth > 32) fail(outer, "nested deeper than 32 levels");
    uint64_t pos = 0;
    auto next = [&](const std::string& var) {
      Element e = element(d + pos, len - pos, var);
      pos += e.total;
      return e;
    };
    Element flags = next(outer);
    if (flags.type != miUINT32 || flags.nbytes < 8) fail(outer, "array flags missing");
    const uint32_t cls = u32(flags.data) & 0xff;
    Element dims = next(outer);
    if (dims.type != miINT32 || dims.nbytes < 8 || dims.nbytes % 4) fail(outer, "dimensions missing");
    double nelem = 1;
    std::string shape;
    for (uint64_t i = 0; i < dims.nbytes / 4; ++i) {
      int32_t k = int32_t(u32(dims.data + 4 * i));
      if (k < 0) fail(outer, "negative dimension");
      nelem *= k;
      shape += (i ? "x" : "") + std::to_string(k);
    }
    Element name = next(outer);
    std::string var = outer;
    if (name.type == miINT8 && name.nbytes > 0) {
      std::string n(reinterpret_cast<const char*>(name.data), size_t(name.nbytes));
      var = outer.empty() ? n : outer + "." + n;
    }
    if (cls == mxCHAR || (cls >= mxDOUBLE && cls <= mxUINT64)) {
      if (nelem == 0) return;
      if (pos >= len) fail(var, shape + " array without data");
      Element data = next(var);
      size_t es = mi_size(data.type);
      if (es == 0) fail(var, "data of unknown storage type " + std::to_string(data.type));
      if (nelem > double(data.nbytes / es))
        fail(var, "dimensions " + shape + " ask for " + std::to_string(uint64_t(nelem)) + " elements, the data holds " +
                      std::to_string(data.nbytes / es));
    } else if (cls == mxCELL || cls == mxSTRUCT) {
      double fields = 1;
      if (cls == mxSTRUCT) {
        Element flen = next(var);
        if (flen.type != miINT32 || flen.nbytes != 4) fail(var, "struct field name length missing");
        uint32_t l = u32(flen.data);
        Element names = next(var);
        fields = l == 0 ? 0 : double(names.nbytes / l);
      }
      const double subs = nelem * fields;
      // Every element is at least one 8-byte tag: more than fit is a lie about the dimensions.
      if (subs > double((len - std::min(pos, len)) / 8))
        fail(var, "dimensions " + shape + " ask for " + std::to_string(uint64_t(subs)) + " elements, the data holds at most " +
                      std::to_string((len - std::min(pos, len)) / 8));
      for (uint64_t i = 0; i < uint64_t(subs) && pos < len; ++i) {
        Element sub = next(var);
        if (sub.type != miMATRIX) fail(var, "cell or field element is not a matrix");
        matrix(sub.data, sub.nbytes, depth + 1, var);
      }
    }
  }

  std::string inflate_capped(const uint8_t* d, uint64_t n, const std::string& var) const {
    const uint64_t cap = memory_limit_bytes();
    std::string out;
    z_stream z{};
    if (inflateInit(&z) != Z_OK) return out;
    z.next_in = const_cast<Bytef*>(d);
    z.avail_in = uInt(std::min<uint64_t>(n, UINT32_MAX));
    char buf[1 << 16];
    int r = Z_OK;
    while (r == Z_OK) {
      z.next_out = reinterpret_cast<Bytef*>(buf);
      z.avail_out = sizeof buf;
      r = inflate(&z, Z_NO_FLUSH);
      out.append(buf, sizeof buf - z.avail_out);
      if (out.size() > cap) {
        inflateEnd(&z);
        throw InputError(file, var, "a compressed variable expands beyond the memory limit (" + format_bytes(double(cap)) + ")");
      }
      if (r == Z_BUF_ERROR && z.avail_in == 0) break;
    }
    inflateEnd(&z);
    return out;  // a damaged stream leaves what did inflate; libmatio reports the rest
  }
};

}  // namespace

void check_mat5_sizes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 128) return;
  Walker w;
  w.file = file.string();
  if (bytes[126] == 'I' && bytes[127] == 'M') w.swap = false;
  else if (bytes[126] == 'M' && bytes[127] == 'I') w.swap = true;
  else return;
  const uint8_t* d = reinterpret_cast<const uint8_t*>(bytes.data());
  uint64_t pos = 128;
  while (bytes.size() - pos >= 8) {
    auto e = w.element(d + pos, bytes.size() - pos, "");
    if (e.type == miMATRIX) {
      w.matrix(e.data, e.nbytes, 0, "");
    } else if (e.type == miCOMPRESSED) {
      std::string inner = w.inflate_capped(e.data, e.nbytes, "");
      const uint8_t* q = reinterpret_cast<const uint8_t*>(inner.data());
      if (inner.size() >= 8) {
        auto m = w.element(q, inner.size(), "");
        if (m.type == miMATRIX) w.matrix(m.data, m.nbytes, 0, "");
      }
    }
    // Compressed elements are not padded to 8 bytes; the others are.
    pos += e.type == miCOMPRESSED ? 8 + e.nbytes : e.total;
  }
}

namespace {

// A MAT 4 type is the decimal number MOPT: M machine format 0-4, O zero, P element type 0-5
// (double, single, int32, int16, uint16, uint8), T 0-2 (numeric, text, sparse).
bool mat4_type_ok(uint32_t t) { return t < 5000 && (t / 100) % 10 == 0 && (t / 10) % 10 <= 5 && t % 10 <= 2; }

uint32_t load_u32(const uint8_t* q, bool swap) {
  uint32_t v;
  std::memcpy(&v, q, 4);
  return swap ? __builtin_bswap32(v) : v;
}

}  // namespace

void check_mat4_sizes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // A version 5 or 7.3 header is what libmatio reads as such: the endian indicator, and the version
  // word 0x0100 or 0x0200 in that byte order. Anything else it reads as MAT 4, from byte 0 (found by
  // fuzz_mat: "MI" with version bytes 00 01 went to the MAT 4 reader, which allocated a 1.9 GB name).
  if (bytes.size() >= 128) {
    const auto b = [&](int i) { return unsigned(static_cast<uint8_t>(bytes[i])); };
    const bool im = bytes[126] == 'I' && bytes[127] == 'M', mi = bytes[126] == 'M' && bytes[127] == 'I';
    const unsigned version = im ? (b(124) | b(125) << 8) : (b(125) | b(124) << 8);
    if ((im || mi) && (version == 0x0100 || version == 0x0200)) return;
  }
  const uint8_t* d = reinterpret_cast<const uint8_t*>(bytes.data());
  const uint64_t size = bytes.size();
  const uint64_t esize[6] = {8, 4, 4, 2, 2, 1};
  uint64_t pos = 0;
  for (int index = 1; size - pos >= 20; ++index) {
    // As libmatio reads it: the type word, byte-swapped if it is not in 0..4052; then the byte order
    // of every other field from the type's machine digit M (0: little-endian, 1: big-endian), not
    // from whether the type needed swapping (a fuzzed header whose type needed swapping but says
    // M = 0 had its 1.7 GB name length read little-endian by libmatio and allocated).
    uint32_t type = load_u32(d + pos, false);
    if (type > 4052) type = __builtin_bswap32(type);
    if (type > 4052 || !mat4_type_ok(type) || type / 1000 > 1) return;  // not MAT 4 libmatio reads: it says so itself
    const bool big_endian_fields = type / 1000 == 1;
    const bool swap = big_endian_fields != (std::endian::native == std::endian::big);
    const uint64_t rows = load_u32(d + pos + 4, swap), cols = load_u32(d + pos + 8, swap);
    const uint64_t parts = load_u32(d + pos + 12, swap) ? 2 : 1, name_len = load_u32(d + pos + 16, swap);
    const std::string field = "variable " + std::to_string(index);
    auto fail = [&](const std::string& what) { throw InputError(file.string(), field, what + " (damaged file?)"); };
    pos += 20;
    if (name_len > size - pos)
      fail("name of " + std::to_string(name_len) + " bytes but only " + std::to_string(size - pos) + " bytes of the file are left");
    pos += name_len;
    // rows and columns are below 2^32 each, so their product fits in 64 bits. A sparse matrix
    // (T = 2) is stored as rows = nonzeros + 1 triplets of at least 3 columns, and libmatio sizes its
    // index arrays by the rows whatever the columns say (fuzz_mat: rows 603979776 with 0 columns
    // made it allocate 2.4 GB from 50 bytes), so it is checked as at least 3 columns.
    const uint64_t shown_cols = type % 10 == 2 ? std::max<uint64_t>(cols, 3) : cols;
    const uint64_t elements = rows * shown_cols, per = esize[(type / 10) % 10] * parts;
    if (elements > (size - pos) / per)
      fail(std::to_string(rows) + "x" + std::to_string(shown_cols) + (type % 10 == 2 ? " sparse" : "") + (parts == 2 ? " complex" : "") +
           " elements of " +
           std::to_string(esize[(type / 10) % 10]) + " bytes but only " + std::to_string(size - pos) + " bytes of the file are left");
    pos += elements * per;
  }
}

}  // namespace ofl
