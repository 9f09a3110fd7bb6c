#include "renderer/view/view_page.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "renderer/plot/vector_plot.h"
#include "renderer/spectral/color.h"
#include "renderer/view/view_assets.h"

namespace ofl {
namespace {

constexpr int64_t kMaxPreviewPixels = 4'000'000;

std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = uint32_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) v |= bytes[i + 2];
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? t[v & 63] : '=';
  }
  return out;
}

// k x k block means of a (h x w x c) grid; partial blocks at the edges average what they hold.
std::vector<float> decimate(const std::vector<float>& v, int w, int h, int c, int k, int* dw, int* dh) {
  *dw = (w + k - 1) / k;
  *dh = (h + k - 1) / k;
  if (k == 1) return v;
  std::vector<double> sum(size_t(*dw) * *dh * c, 0.0);
  std::vector<int> n(size_t(*dw) * *dh, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      size_t cell = size_t(y / k) * *dw + x / k;
      ++n[cell];
      for (int j = 0; j < c; ++j) sum[cell * c + j] += v[(size_t(y) * w + x) * c + j];
    }
  std::vector<float> out(sum.size());
  for (size_t i = 0; i < out.size(); ++i) out[i] = float(sum[i] / n[i / c]);
  return out;
}

// float16 of value / scale[channel]; scale = the channel's largest magnitude (1 when all zero).
std::vector<uint8_t> half_cube(const std::vector<float>& v, int c, std::vector<double>* scale) {
  scale->assign(c, 0.0);
  for (size_t i = 0; i < v.size(); ++i) (*scale)[i % c] = std::max((*scale)[i % c], double(std::fabs(v[i])));
  for (double& s : *scale)
    if (!(s > 0) || !std::isfinite(s)) s = 1.0;
  std::vector<uint8_t> out(v.size() * 2);
  for (size_t i = 0; i < v.size(); ++i) {
    uint16_t h = float_to_half(float(v[i] / (*scale)[i % c]));
    out[2 * i] = uint8_t(h & 0xff);
    out[2 * i + 1] = uint8_t(h >> 8);
  }
  return out;
}

// 8-bit sRGB (RGB triplets) of the grid through `to_rgb`, sampled every `k` pixels, scaled so that
// the 99.5th percentile of the brightest channel is 1; the gain used goes to *gain.
std::vector<uint8_t> srgb_preview(const std::vector<float>& v, const ViewImage& im, int k, int pw, int ph, double* gain) {
  const int c = im.num_channels();
  std::vector<float> lin(size_t(pw) * ph * 3);
  std::vector<float> peak;
  for (int y = 0; y < ph; ++y)
    for (int x = 0; x < pw; ++x) {
      const float* p = &v[(size_t(std::min(y * k, im.height - 1)) * im.width + std::min(x * k, im.width - 1)) * c];
      float m = 0;
      for (int j = 0; j < 3; ++j) {
        double s = 0;
        for (int b = 0; b < c; ++b) s += im.to_rgb[j][b] * p[b];
        lin[(size_t(y) * pw + x) * 3 + j] = float(s);
        m = std::max(m, float(s));
      }
      peak.push_back(m);
    }
  size_t q = std::min(peak.size() - 1, size_t(0.995 * double(peak.size())));
  std::nth_element(peak.begin(), peak.begin() + q, peak.end());
  *gain = peak[q] > 0 ? 1.0 / peak[q] : 1.0;
  std::vector<uint8_t> out(lin.size());
  for (size_t i = 0; i < lin.size(); ++i) out[i] = uint8_t(std::lround(255.0 * srgb_encode(lin[i] * *gain)));
  return out;
}

std::vector<uint8_t> material_plane(const ViewImage& im, int k, int pw, int ph) {
  std::vector<uint8_t> out(size_t(pw) * ph);
  for (int y = 0; y < ph; ++y)
    for (int x = 0; x < pw; ++x) {
      float m = im.material[size_t(std::min(y * k, im.height - 1)) * im.width + std::min(x * k, im.width - 1)];
      out[size_t(y) * pw + x] = uint8_t(std::clamp(int(std::lround(m)) + 2, 0, 255));  // -2 LED, -1 none
    }
  return out;
}

std::string blob(const std::string& id, const std::vector<uint8_t>& bytes) {
  return "<script type=\"text/plain\" id=\"" + id + "\">" + base64(bytes) + "</script>\n";
}

// One image's metadata (JSON) and data blobs.
std::string image_section(const ViewImage& im, int index, const ViewOptions& o, nlohmann::json* meta) {
  const int c = im.num_channels();
  const int k = view_decimation(im.width, im.height, c, o.max_values);
  int dw = 0, dh = 0;
  std::vector<double> scale, fscale;
  std::string prefix = "ofl-" + std::to_string(index) + "-", html;
  html += blob(prefix + "cube", half_cube(decimate(im.values, im.width, im.height, c, k, &dw, &dh), c, &scale));
  const bool fluo = !im.fluorescence.empty();
  if (fluo) html += blob(prefix + "fluo", half_cube(decimate(im.fluorescence, im.width, im.height, c, k, &dw, &dh), c, &fscale));
  int kp = 1;
  while (int64_t((im.width + kp - 1) / kp) * ((im.height + kp - 1) / kp) > kMaxPreviewPixels) ++kp;
  const int pw = (im.width + kp - 1) / kp, ph = (im.height + kp - 1) / kp;
  double gain = 1, fgain = 1;
  html += blob(prefix + "preview", srgb_preview(im.values, im, kp, pw, ph, &gain));
  if (fluo) html += blob(prefix + "fpreview", srgb_preview(im.fluorescence, im, kp, pw, ph, &fgain));
  if (!im.material.empty()) html += blob(prefix + "material", material_plane(im, kp, pw, ph));
  nlohmann::json notes = im.notes;
  if (k > 1)
    notes.push_back("spectra are " + std::to_string(k) + " x " + std::to_string(k) + " pixel means (the image has " +
                    std::to_string(int64_t(im.width) * im.height * c) + " values; oralfluor view --max-values to keep more)");
  *meta = {{"file", im.file},       {"kind", im.kind},          {"units", im.units},       {"width", im.width},
           {"height", im.height},   {"pixel_size", im.pixel_size}, {"k", k},             {"dw", dw},
           {"dh", dh},              {"kp", kp},                 {"pw", pw},                {"ph", ph},
           {"channels", im.channels}, {"wavelengths", im.wavelengths}, {"scale", scale}, {"fscale", fscale},
           {"has_fluo", fluo},      {"has_material", !im.material.empty()}, {"material_names", im.material_names},
           {"to_rgb", im.to_rgb},   {"to_xyz", im.wavelengths.empty() ? nlohmann::json(nullptr) : nlohmann::json(im.to_xyz)},
           {"preview_gain", gain},  {"fluo_gain", fgain},       {"notes", notes}};
  return html;
}

}  // namespace

uint16_t float_to_half(float f) {
  uint32_t x;
  std::memcpy(&x, &f, 4);
  const uint32_t sign = (x >> 16) & 0x8000u;
  const int32_t exp = int32_t((x >> 23) & 0xff) - 127 + 15;
  uint32_t mant = x & 0x7fffffu;
  if (((x >> 23) & 0xff) == 0xff) return uint16_t(sign | 0x7c00u | (mant ? 0x200u : 0));  // inf, NaN
  if (exp >= 31) return uint16_t(sign | 0x7c00u);                                          // overflow
  if (exp <= 0) {                                                                           // subnormal or zero
    if (exp < -10) return uint16_t(sign);
    mant |= 0x800000u;
    const int shift = 14 - exp;
    uint32_t h = mant >> shift, rem = mant & ((1u << shift) - 1), half = 1u << (shift - 1);
    if (rem > half || (rem == half && (h & 1u))) ++h;
    return uint16_t(sign | h);
  }
  uint32_t h = (uint32_t(exp) << 10) | (mant >> 13), rem = mant & 0x1fffu;
  if (rem > 0x1000u || (rem == 0x1000u && (h & 1u))) ++h;  // may carry into the exponent: still right
  return uint16_t(sign | h);
}

float half_to_float(uint16_t h) {
  const uint32_t sign = uint32_t(h & 0x8000u) << 16, exp = (h >> 10) & 0x1fu, mant = h & 0x3ffu;
  float v;
  if (exp == 0) v = std::ldexp(float(mant), -24);
  else if (exp == 31) v = mant ? NAN : INFINITY;
  else v = std::ldexp(float(mant | 0x400u), int(exp) - 25);
  return sign ? -v : v;
}

int view_decimation(int width, int height, int channels, int64_t max_values) {
  int k = 1;
  while (int64_t((width + k - 1) / k) * ((height + k - 1) / k) * channels > std::max<int64_t>(max_values, 1) &&
         k < std::max(width, height))
    ++k;
  return k;
}

std::string view_page_html(const std::vector<ViewImage>& images, const ViewOptions& o) {
  std::string title = o.title;
  if (title.empty())
    for (auto& im : images) title += (title.empty() ? "" : " | ") + std::filesystem::path(im.file).filename().string();
  nlohmann::json meta = {{"title", title}, {"images", nlohmann::json::array()}};
  std::string blobs;
  for (size_t i = 0; i < images.size(); ++i) {
    nlohmann::json m;
    blobs += image_section(images[i], int(i), o, &m);
    meta["images"].push_back(m);
  }
  std::string json = meta.dump();
  // Inside a script element "</" would end it: JSON strings may hold it (file names).
  for (size_t p = json.find("</"); p != std::string::npos; p = json.find("</", p + 2)) json.replace(p, 2, "<\\/");
  return std::string("<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>oralfluor view: ") +
         svg_escape(title) + "</title>\n<style>" + view_style() + "</style></head>\n<body>\n" + view_body() +
         "<script type=\"application/json\" id=\"ofl-meta\">" + json + "</script>\n" + blobs + "<script>" +
         view_script() + "</script>\n</body></html>\n";
}

}  // namespace ofl
