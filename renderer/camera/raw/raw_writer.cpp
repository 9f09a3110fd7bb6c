#include "renderer/camera/raw/raw_writer.h"

#include <cstdlib>
#include <ctime>

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/process/library_stderr.h"
#include "renderer/image/image_file.h"

namespace ofl {

nlohmann::json RawMetadata::numbers_json() const {
  return {{"format", "oralfluor-raw"},
          {"version", 1},
          {"width", width},
          {"f_number", f_number},
          {"focal_length_mm", focal_length_mm},
          {"height", height},
          {"cfa_pattern", cfa_name(cfa)},
          {"black_level_dn", black_level_dn},
          {"white_level_dn", white_level_dn},
          {"adc_max_dn", adc_max_dn},
          {"bit_depth", bit_depth},
          {"exposure_s", exposure_s},
          {"system_gain_dn_per_e", system_gain_dn_per_e},
          {"analog_gain", analog_gain},
          {"total_gain_dn_per_e", total_gain()},
          {"full_well_e", full_well_e},
          {"noise", noise},
          {"seed", seed},
          {"camera_name", camera_name}};
}

nlohmann::json RawMetadata::sidecar_json() const {
  nlohmann::json j = numbers_json();
  for (auto it = extra.begin(); it != extra.end(); ++it) j[it.key()] = it.value();
  return j;
}

RawMetadata RawMetadata::from_json(const JsonNode& n) {
  RawMetadata m;
  if (n.string_or("format", "") != "oralfluor-raw") n.fail("not an oralfluor raw description (\"format\" is not \"oralfluor-raw\")");
  m.width = n.at("width").integer(1);
  m.height = n.at("height").integer(1);
  auto p = parse_cfa_name(n.at("cfa_pattern").string());
  if (!p) n.at("cfa_pattern").fail("unknown CFA pattern");
  m.cfa = *p;
  m.black_level_dn = n.at("black_level_dn").integer(0, 65535);
  m.white_level_dn = n.at("white_level_dn").integer(0, 65535);
  m.adc_max_dn = n.integer_or("adc_max_dn", 65535, 1, 65535);
  m.bit_depth = n.integer_or("bit_depth", 16, 1, 16);
  m.exposure_s = n.number_or("exposure_s", 0.0, 0.0);
  m.f_number = n.number_or("f_number", 0.0, 0.0);
  m.focal_length_mm = n.number_or("focal_length_mm", 0.0, 0.0);
  m.system_gain_dn_per_e = n.number_or("system_gain_dn_per_e", 1.0, 0.0);
  m.analog_gain = n.number_or("analog_gain", 1.0, 0.0);
  m.full_well_e = n.number_or("full_well_e", 0.0, 0.0);
  m.noise = n.boolean_or("noise", true);
  if (auto s = n.find("seed")) m.seed = s->raw().get<uint64_t>();
  m.camera_name = n.string_or("camera_name", "");
  if (m.white_level_dn <= m.black_level_dn) n.at("white_level_dn").fail("white level must exceed the black level");
  return m;
}

std::filesystem::path sidecar_path(const std::filesystem::path& tiff) {
  auto p = tiff;
  p.replace_extension(".json");
  return p;
}

void write_raw_tiff(const std::filesystem::path& file, const std::vector<uint16_t>& dn, const RawMetadata& m) {
  OIIO::ImageSpec spec(m.width, m.height, 1, OIIO::TypeDesc::UINT16);
  spec.channelnames = {"Y"};
  spec.attribute("compression", "zip");
  spec.attribute("oiio:BitsPerSample", 16);
  spec.attribute("ImageDescription", m.numbers_json().dump());
  spec.attribute("Make", "oralfluor");
  spec.attribute("Model", m.camera_name);
  spec.attribute("Software", "oralfluor camera");
  write_image_file(file, spec, dn.data());
}

void write_raw_sidecar(const std::filesystem::path& file, const RawMetadata& m) {
  write_file_atomic(file, m.sidecar_json().dump(1) + "\n");
}

// ----------------------------------------------------------------------------------------------
// DNG: a little-endian TIFF with one IFD holding the CFA image and the DNG tags a reader needs.

namespace {

enum TiffType : uint16_t { kByte = 1, kAscii = 2, kShort = 3, kLong = 4, kRational = 5, kSRational = 10 };

struct TiffEntry {
  uint16_t tag;
  uint16_t type;
  uint32_t count;
  std::vector<uint8_t> data;  // little-endian payload
};

void put16(std::vector<uint8_t>& b, uint16_t v) { b.push_back(v & 0xff); b.push_back(v >> 8); }
void put32(std::vector<uint8_t>& b, uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back((v >> (8 * i)) & 0xff);
}

TiffEntry shorts(uint16_t tag, std::initializer_list<uint16_t> v) {
  TiffEntry e{tag, kShort, static_cast<uint32_t>(v.size()), {}};
  for (auto x : v) put16(e.data, x);
  return e;
}
TiffEntry longs(uint16_t tag, std::initializer_list<uint32_t> v) {
  TiffEntry e{tag, kLong, static_cast<uint32_t>(v.size()), {}};
  for (auto x : v) put32(e.data, x);
  return e;
}
TiffEntry bytes(uint16_t tag, std::vector<uint8_t> v) {
  return {tag, kByte, static_cast<uint32_t>(v.size()), std::move(v)};
}
TiffEntry ascii(uint16_t tag, const std::string& s) {
  std::vector<uint8_t> d(s.begin(), s.end());
  d.push_back(0);
  return {tag, kAscii, static_cast<uint32_t>(d.size()), std::move(d)};
}
// Rationals with a fixed denominator precise enough for matrices and exposure times.
TiffEntry rationals(uint16_t tag, const std::vector<double>& v, bool is_signed) {
  TiffEntry e{tag, static_cast<uint16_t>(is_signed ? kSRational : kRational), static_cast<uint32_t>(v.size()), {}};
  for (double x : v) {
    uint32_t den = 1000000;
    double num = std::round(x * den);
    while (std::fabs(num) > 2.0e9 && den > 1) {
      den /= 10;
      num = std::round(x * den);
    }
    if (is_signed) put32(e.data, static_cast<uint32_t>(static_cast<int32_t>(num)));
    else put32(e.data, static_cast<uint32_t>(std::max(0.0, num)));
    put32(e.data, den);
  }
  return e;
}

}  // namespace

std::string capture_time_text(const std::filesystem::path& radiance_file) {
  std::time_t t = 0;
  bool known = false;
  if (const char* e = std::getenv("SOURCE_DATE_EPOCH")) {
    char* end = nullptr;
    long long v = std::strtoll(e, &end, 10);
    if (end != e && *end == 0 && v >= 0) t = static_cast<std::time_t>(v), known = true;
  }
  struct stat st {};
  if (!known && !radiance_file.empty() && ::stat(radiance_file.c_str(), &st) == 0) t = st.st_mtime, known = true;
  if (!known) return "";
  std::tm tm{};
  gmtime_r(&t, &tm);
  char b[32];
  std::strftime(b, sizeof b, "%Y:%m:%d %H:%M:%S", &tm);
  return b;
}

void write_dng(const std::filesystem::path& file, const std::vector<uint16_t>& dn, const RawMetadata& m,
               const DngColor& color) {
  const uint32_t image_bytes = static_cast<uint32_t>(dn.size() * 2);
  std::vector<TiffEntry> e;
  e.push_back(longs(254, {0}));                                     // NewSubFileType: main image
  e.push_back(longs(256, {static_cast<uint32_t>(m.width)}));        // ImageWidth
  e.push_back(longs(257, {static_cast<uint32_t>(m.height)}));       // ImageLength
  e.push_back(shorts(258, {16}));                                   // BitsPerSample
  e.push_back(shorts(259, {1}));                                    // Compression: none
  e.push_back(shorts(262, {32803}));                                // PhotometricInterpretation: CFA
  e.push_back(ascii(271, "oralfluor"));                             // Make
  e.push_back(ascii(272, m.camera_name.empty() ? "camera" : m.camera_name));  // Model
  e.push_back(longs(273, {0}));                                     // StripOffsets (patched below)
  e.push_back(shorts(274, {1}));                                    // Orientation
  e.push_back(shorts(277, {1}));                                    // SamplesPerPixel
  e.push_back(longs(278, {static_cast<uint32_t>(m.height)}));       // RowsPerStrip
  e.push_back(longs(279, {image_bytes}));                           // StripByteCounts
  e.push_back(shorts(284, {1}));                                    // PlanarConfiguration
  e.push_back(ascii(305, "oralfluor camera"));                      // Software
  e.push_back(shorts(33421, {2, 2}));                               // CFARepeatPatternDim
  auto cell = cfa_cell(m.cfa);
  e.push_back(bytes(33422, {cell[0], cell[1], cell[2], cell[3]}));  // CFAPattern (0 R, 1 G, 2 B)
  if (!m.capture_time.empty()) e.push_back(ascii(306, m.capture_time));  // DateTime
  e.push_back(rationals(33434, {m.exposure_s}, false));             // ExposureTime
  if (m.f_number > 0) e.push_back(rationals(33437, {m.f_number}, false));  // FNumber
  if (!m.capture_time.empty()) e.push_back(ascii(36867, m.capture_time));  // DateTimeOriginal
  if (m.focal_length_mm > 0) e.push_back(rationals(37386, {m.focal_length_mm}, false));  // FocalLength
  e.push_back(bytes(50706, {1, 4, 0, 0}));                          // DNGVersion
  e.push_back(bytes(50707, {1, 1, 0, 0}));                          // DNGBackwardVersion
  e.push_back(ascii(50708, "oralfluor " + (m.camera_name.empty() ? std::string("camera") : m.camera_name)));
  e.push_back(bytes(50710, {0, 1, 2}));                             // CFAPlaneColor
  e.push_back(shorts(50711, {1}));                                  // CFALayout: rectangular
  e.push_back(longs(50714, {static_cast<uint32_t>(m.black_level_dn)}));  // BlackLevel
  e.push_back(longs(50717, {static_cast<uint32_t>(m.white_level_dn)}));  // WhiteLevel
  e.push_back(rationals(50721, std::vector<double>(color.xyz_to_camera.begin(), color.xyz_to_camera.end()), true));
  e.push_back(rationals(50728, {color.as_shot_neutral[0], color.as_shot_neutral[1], color.as_shot_neutral[2]}, false));
  e.push_back(shorts(50778, {21}));                                 // CalibrationIlluminant1: D65
  std::sort(e.begin(), e.end(), [](const TiffEntry& a, const TiffEntry& b) { return a.tag < b.tag; });

  // Layout: header (8) | IFD (2 + 12 n + 4) | values longer than 4 bytes | image.
  const uint32_t ifd_offset = 8;
  const uint32_t ifd_size = 2 + 12 * static_cast<uint32_t>(e.size()) + 4;
  uint32_t data_offset = ifd_offset + ifd_size;
  std::vector<uint32_t> value_offset(e.size(), 0);
  for (size_t i = 0; i < e.size(); ++i)
    if (e[i].data.size() > 4) {
      value_offset[i] = data_offset;
      data_offset += static_cast<uint32_t>(e[i].data.size() + (e[i].data.size() & 1));  // word aligned
    }
  const uint32_t image_offset = data_offset;
  for (auto& x : e)
    if (x.tag == 273) {
      x.data.clear();
      put32(x.data, image_offset);
    }

  std::vector<uint8_t> out;
  out.reserve(image_offset + image_bytes);
  out.push_back('I');
  out.push_back('I');
  put16(out, 42);
  put32(out, ifd_offset);
  put16(out, static_cast<uint16_t>(e.size()));
  for (size_t i = 0; i < e.size(); ++i) {
    put16(out, e[i].tag);
    put16(out, e[i].type);
    put32(out, e[i].count);
    if (e[i].data.size() > 4) {
      put32(out, value_offset[i]);
    } else {
      std::vector<uint8_t> v = e[i].data;
      v.resize(4, 0);
      out.insert(out.end(), v.begin(), v.end());
    }
  }
  put32(out, 0);  // no next IFD
  for (size_t i = 0; i < e.size(); ++i)
    if (e[i].data.size() > 4) {
      out.insert(out.end(), e[i].data.begin(), e[i].data.end());
      if (e[i].data.size() & 1) out.push_back(0);
    }
  for (uint16_t v : dn) put16(out, v);
  write_file_atomic(file, std::string(reinterpret_cast<const char*>(out.data()), out.size()));
}

// ----------------------------------------------------------------------------------------------

RawImage read_raw(const std::filesystem::path& tiff) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(tiff, ec)) throw InputError(tiff.string(), "", "file not found");
  LibraryStderr quiet({"libpng "});  // see library_error in renderer/image/image_file.h
  auto in = OIIO::ImageInput::open(tiff.string());
  if (!in) throw InputError(tiff.string(), "", "cannot read image: " + library_error(OIIO::geterror(), quiet.end()));
  const OIIO::ImageSpec& spec = in->spec();
  check_image_spec(tiff, spec, sizeof(uint16_t));
  if (spec.nchannels != 1)
    throw InputError(tiff.string(), "", "not a raw mosaic: " + std::to_string(spec.nchannels) +
                                            " channels (expected one, as written by `oralfluor camera`)");
  RawImage r;
  r.width = spec.width;
  r.height = spec.height;
  r.dn.resize(static_cast<size_t>(r.width) * r.height);
  const bool ok = in->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT16, r.dn.data());
  std::vector<std::string> library = quiet.end();
  if (!ok) throw InputError(tiff.string(), "", "cannot read pixels: " + library_error(in->geterror(), library));
  std::string description = spec.get_string_attribute("ImageDescription");
  in->close();

  r.sidecar_file = sidecar_path(tiff);
  if (std::filesystem::is_regular_file(r.sidecar_file, ec)) {
    JsonFile f = JsonFile::load(r.sidecar_file);
    r.meta = RawMetadata::from_json(f.root());
    r.sidecar = f.doc();
  } else {
    r.sidecar_file.clear();
    nlohmann::json d;
    try {
      d = nlohmann::json::parse(description);
    } catch (const std::exception&) {
      throw InputError(tiff.string(), "ImageDescription",
                       "no raw.json sidecar next to the TIFF and no oralfluor metadata in the TIFF; cannot tell the "
                       "CFA pattern and black level");
    }
    JsonFile f = JsonFile::from(d, tiff.string() + " (ImageDescription)");
    r.meta = RawMetadata::from_json(f.root());
  }
  if (r.meta.width != r.width || r.meta.height != r.height)
    throw InputError(r.sidecar_file.empty() ? tiff.string() : r.sidecar_file.string(), "/width",
                     "metadata says " + std::to_string(r.meta.width) + "x" + std::to_string(r.meta.height) +
                         " but the TIFF is " + std::to_string(r.width) + "x" + std::to_string(r.height));
  return r;
}

}  // namespace ofl
