#include "renderer/image/spectral_exr.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numeric>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/exr_header.h"
#include "renderer/spectral/color.h"

namespace ofl {

std::string spectral_channel_name(double nm) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "S0.%.6fnm", nm);
  std::string s = buf;
  // The layout writes the decimal separator as a comma.
  auto dot = s.find('.', 3);
  if (dot != std::string::npos) s[dot] = ',';
  return s;
}

bool parse_spectral_channel_name(const std::string& name, double* nm) {
  if (name.size() < 6 || name.rfind("S0.", 0) != 0 || name.substr(name.size() - 2) != "nm") return false;
  std::string num = name.substr(3, name.size() - 5);
  std::replace(num.begin(), num.end(), ',', '.');
  char* end = nullptr;
  double v = std::strtod(num.c_str(), &end);
  if (end == num.c_str() || *end != '\0' || !(v > 0)) return false;
  *nm = v;
  return true;
}

std::vector<float> spectral_to_linear_srgb(const SpectralImage& img, double white) {
  ColorMatching m = cie1931_on_bands(img.band_lo(), img.band_hi());
  std::vector<double> w(img.bands());
  for (int b = 0; b < img.bands(); ++b) w[b] = img.band_hi()[b] - img.band_lo()[b];
  double ywhite = 0;
  for (int b = 0; b < img.bands(); ++b) ywhite += m.y[b] * w[b] * white;
  double norm = ywhite > 0 ? 1.0 / ywhite : 1.0;
  std::vector<float> rgb(static_cast<size_t>(img.width) * img.height * 3);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const float* p = img.pixel(x, y);
      std::array<double, 3> xyz{0, 0, 0};
      for (int b = 0; b < img.bands(); ++b) {
        xyz[0] += m.x[b] * w[b] * p[b];
        xyz[1] += m.y[b] * w[b] * p[b];
        xyz[2] += m.z[b] * w[b] * p[b];
      }
      for (auto& c : xyz) c *= norm;
      auto lin = xyz_to_linear_srgb(xyz);
      size_t o = (static_cast<size_t>(y) * img.width + x) * 3;
      for (int c = 0; c < 3; ++c) rgb[o + c] = static_cast<float>(lin[c]);
    }
  return rgb;
}

namespace {
// An Imf::OStream into a string (OpenEXR seeks back to fill in the line offset table).
class MemoryOStream : public Imf::OStream {
 public:
  MemoryOStream() : Imf::OStream("memory") {}
  void write(const char c[], int n) override {
    if (pos_ == bytes.size()) {
      bytes.append(c, size_t(n));  // the usual case: no zero fill before the copy
    } else {
      if (pos_ + size_t(n) > bytes.size()) bytes.resize(pos_ + size_t(n));
      std::memcpy(bytes.data() + pos_, c, size_t(n));
    }
    pos_ += size_t(n);
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = size_t(pos); }
  std::string bytes;

 private:
  size_t pos_ = 0;
};
}  // namespace

namespace {

// The EXR file's bytes, encoded in memory; `file` names errors.
std::string encode_spectral_exr(const SpectralImage& img, const std::string& file) {
  Imf::Header header(img.width, img.height);
  header.insert("spectralLayoutVersion", Imf::StringAttribute("1.0"));
  header.insert("emissiveUnits", Imf::StringAttribute("W.m^-2.sr^-1"));
  for (auto& [k, v] : img.attributes) header.insert(k, Imf::StringAttribute(v));
  // ZIP chunks of 16 lines, stored without deflating (level 0): float radiance is noise down to its
  // last mantissa bits, so deflating saved only 6 % of the flat patch's file (19 % of the tongue's)
  // at 2.6 CPU s per 55 MB, a sixth of the whole render's CPU time; stored, 0.3 s (benchmarks/RESULTS.md,
  // side by side with pbrt-v4).
  header.compression() = Imf::ZIP_COMPRESSION;
  header.zipCompressionLevel() = 0;

  std::vector<float> rgb = spectral_to_linear_srgb(img, 1.0);
  std::vector<std::string> names;
  for (double nm : img.band_nm) names.push_back(spectral_channel_name(nm));
  for (auto& n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
  for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
  const bool has_fl = img.fluorescence.size() == img.data.size();
  if (has_fl)
    for (auto& n : names) header.channels().insert("fluorescence." + n, Imf::Channel(Imf::FLOAT));
  for (auto& [name, plane] : img.aovs)
    if (plane.size() == size_t(img.width) * img.height) header.channels().insert(name, Imf::Channel(Imf::FLOAT));

  Imf::FrameBuffer fb;
  size_t px = sizeof(float) * img.bands();
  for (int b = 0; b < img.bands(); ++b)
    fb.insert(names[b], Imf::Slice(Imf::FLOAT, (char*)(img.data.data() + b), px, px * img.width));
  const char* rgbn[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c)
    fb.insert(rgbn[c], Imf::Slice(Imf::FLOAT, (char*)(rgb.data() + c), 3 * sizeof(float), 3 * sizeof(float) * img.width));
  if (has_fl)
    for (int b = 0; b < img.bands(); ++b)
      fb.insert("fluorescence." + names[b], Imf::Slice(Imf::FLOAT, (char*)(img.fluorescence.data() + b), px, px * img.width));
  for (auto& [name, plane] : img.aovs)
    if (plane.size() == size_t(img.width) * img.height)
      fb.insert(name, Imf::Slice(Imf::FLOAT, (char*)plane.data(), sizeof(float), sizeof(float) * img.width));
  MemoryOStream mem;
  // Stored, the file is a little more than its pixels: one allocation instead of a doubling series
  // of copies.
  size_t channels = 0;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) ++channels;
  mem.bytes.reserve(size_t(img.width) * img.height * sizeof(float) * channels + (size_t(1) << 16));
  try {
    Imf::OutputFile out(mem, header);
    out.setFrameBuffer(fb);
    out.writePixels(img.height);
  } catch (const std::exception& e) {
    throw InputError(file, "", std::string("cannot write EXR: ") + e.what());
  }
  return mem.bytes;
}

}  // namespace

// Encoded in memory, then written with every write checked and renamed into place
// (write_file_atomic): readers never see a half-written image, a full disk is an error.
void write_spectral_exr(const std::filesystem::path& file, const SpectralImage& img) {
  write_file_atomic(file, encode_spectral_exr(img, file.string()));
}

void set_exr_threads(int threads) { Imf::setGlobalThreadCount(std::max(0, threads)); }

std::string spectral_exr_bytes(const SpectralImage& img) { return encode_spectral_exr(img, "(memory)"); }

SpectralImage read_spectral_exr(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(file.string(), "", "file not found");
  if (!check_exr_header(file).is_exr) throw InputError(file.string(), "", "not an OpenEXR file");
  SpectralImage img;
  try {
    Imf::InputFile in(file.string().c_str());
    const Imf::Header& h = in.header();
    auto dw = h.dataWindow();
    img.width = dw.max.x - dw.min.x + 1;
    img.height = dw.max.y - dw.min.y + 1;
    std::vector<std::pair<double, std::string>> chans;
    std::vector<std::string> aov_names;
    bool has_fl = true;
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
      double nm;
      std::string name = it.name();
      if (parse_spectral_channel_name(name, &nm)) chans.push_back({nm, name});
      else if (name.rfind("aov.", 0) == 0) aov_names.push_back(name);
    }
    for (auto& c : chans) has_fl = has_fl && h.channels().findChannel("fluorescence." + c.second);
    if (chans.empty())
      throw InputError(file.string(), "channels", "no spectral channels (expected names like S0.550,000000nm)");
    std::sort(chans.begin(), chans.end());
    for (auto& c : chans) img.band_nm.push_back(c.first);
    for (auto it = h.begin(); it != h.end(); ++it) {
      if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) img.attributes[it.name()] = s->value();
    }
    img.data.assign(static_cast<size_t>(img.width) * img.height * img.bands(), 0.0f);
    Imf::FrameBuffer fb;
    // Slice::Make places the pointer at the data window's origin with integer arithmetic: moving a
    // pointer outside its array by the window's offset is undefined behaviour (fuzz_spectral_exr,
    // UBSan, a window whose origin is negative).
    size_t px = sizeof(float) * img.bands();
    for (int b = 0; b < img.bands(); ++b)
      fb.insert(chans[b].second, Imf::Slice::Make(Imf::FLOAT, img.data.data() + b, dw, px, px * img.width));
    if (has_fl && !chans.empty()) {
      img.fluorescence.assign(img.data.size(), 0.0f);
      for (int b = 0; b < img.bands(); ++b)
        fb.insert("fluorescence." + chans[b].second, Imf::Slice::Make(Imf::FLOAT, img.fluorescence.data() + b, dw, px, px * img.width));
    }
    for (auto& name : aov_names) {
      auto& plane = img.aovs[name];
      plane.assign(size_t(img.width) * img.height, 0.0f);
      fb.insert(name, Imf::Slice::Make(Imf::FLOAT, plane.data(), dw, sizeof(float), sizeof(float) * img.width));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(file.string(), "", "cannot read EXR: " + printable(e.what(), 200));
  }
  return img;
}

}  // namespace ofl
