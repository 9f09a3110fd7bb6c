#include "renderer/view/view_image.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "renderer/camera/elements/cfa_pattern.h"
#include "renderer/camera/raw/raw_writer.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/spectral/color.h"

namespace ofl {
namespace {

std::string lower_extension(const std::filesystem::path& f) {
  std::string e = f.extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

std::string nm_label(double nm) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g nm", nm);
  return buf;
}

// CIE 1931 XYZ and linear sRGB weights per band (band widths folded in), as spectral_exr's preview.
void spectral_colour_weights(const SpectralImage& img, ViewImage& v) {
  auto lo = img.band_lo(), hi = img.band_hi();
  ColorMatching cmf = cie1931_on_bands(lo, hi);
  for (int k = 0; k < 3; ++k) {
    v.to_xyz[k].assign(img.bands(), 0.0);
    v.to_rgb[k].assign(img.bands(), 0.0);
  }
  for (int b = 0; b < img.bands(); ++b) {
    const double w = hi[b] - lo[b];
    std::array<double, 3> xyz = {cmf.x[b] * w, cmf.y[b] * w, cmf.z[b] * w};
    std::array<double, 3> rgb = xyz_to_linear_srgb(xyz);
    for (int k = 0; k < 3; ++k) {
      v.to_xyz[k][b] = xyz[k];
      v.to_rgb[k][b] = rgb[k];
    }
  }
}

void identity_rgb(ViewImage& v) {
  for (int k = 0; k < 3; ++k) {
    v.to_rgb[k].assign(3, 0.0);
    v.to_rgb[k][k] = 1.0;
  }
}

ViewImage load_radiance(const std::filesystem::path& file) {
  SpectralImage img = read_spectral_exr(file);
  if (img.width <= 0 || img.height <= 0 || img.bands() == 0) throw InputError(file.string(), "", "empty spectral image");
  ViewImage v;
  v.file = file.string();
  v.kind = "radiance";
  v.units = "W sr^-1 m^-2 nm^-1";
  v.width = img.width;
  v.height = img.height;
  v.wavelengths = img.band_nm;
  for (double nm : img.band_nm) v.channels.push_back(nm_label(nm));
  v.values = std::move(img.data);
  v.fluorescence = std::move(img.fluorescence);
  if (auto it = img.aovs.find("aov.material"); it != img.aovs.end()) v.material = it->second;
  if (auto it = img.attributes.find("oralfluor.materials"); it != img.attributes.end()) {
    nlohmann::json names = nlohmann::json::parse(it->second, nullptr, false);
    if (names.is_array())
      for (auto& n : names) v.material_names.push_back(n.is_string() ? n.get<std::string>() : n.dump());
  }
  spectral_colour_weights(img, v);
  if (v.fluorescence.empty()) v.notes.push_back("no fluorescence layer in this EXR (render keeps one by default)");
  return v;
}

// electrons.exr: R, G, B expected electrons per pixel (renderer/camera/camera_pipeline.h).
ViewImage load_electrons(const std::filesystem::path& file, OIIO::ImageInput& in) {
  const OIIO::ImageSpec& spec = in.spec();
  std::vector<int> idx;
  for (const char* c : {"R", "G", "B"}) {
    auto it = std::find(spec.channelnames.begin(), spec.channelnames.end(), c);
    idx.push_back(int(it - spec.channelnames.begin()));
  }
  std::vector<float> all(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in.read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw InputError(file.string(), "", "cannot read the pixels: " + in.geterror());
  ViewImage v;
  v.file = file.string();
  v.kind = "electrons";
  v.units = "e- (expected)";
  v.width = spec.width;
  v.height = spec.height;
  v.channels = {"R", "G", "B"};
  v.values.resize(size_t(v.width) * v.height * 3);
  for (size_t i = 0; i < size_t(v.width) * v.height; ++i)
    for (int c = 0; c < 3; ++c) v.values[i * 3 + c] = all[i * spec.nchannels + idx[c]];
  identity_rgb(v);
  v.notes.push_back("camera R, G, B expected electrons (noise free) at every pixel; colours are the channels as sRGB primaries");
  return v;
}

// raw.tiff: one value per 2x2 CFA cell and colour (G: the mean of the two), minus the black level.
ViewImage load_raw(const std::filesystem::path& file) {
  RawImage r = read_raw(file);
  if (r.width < 2 || r.height < 2) throw InputError(file.string(), "", "a raw mosaic needs at least 2 x 2 pixels");
  ViewImage v;
  v.file = file.string();
  v.kind = "raw";
  v.units = "DN above black";
  v.width = r.width / 2;
  v.height = r.height / 2;
  v.pixel_size = 2;
  v.channels = {"R", "G", "B"};
  v.values.assign(size_t(v.width) * v.height * 3, 0.0f);
  const std::string cfa = cfa_name(r.meta.cfa);
  for (int cy = 0; cy < v.height; ++cy)
    for (int cx = 0; cx < v.width; ++cx) {
      float* out = &v.values[(size_t(cy) * v.width + cx) * 3];
      for (int k = 0; k < 4; ++k) {
        int x = 2 * cx + k % 2, y = 2 * cy + k / 2;
        float dn = float(r.dn[size_t(y) * r.width + x]) - float(r.meta.black_level_dn);
        int c = cfa[k] == 'R' ? 0 : cfa[k] == 'G' ? 1 : 2;
        out[c] += c == 1 ? 0.5f * dn : dn;
      }
    }
  identity_rgb(v);
  v.notes.push_back("raw " + cfa + " mosaic: one R, mean G and B value per 2x2 cell, black level " +
                    std::to_string(int(r.meta.black_level_dn)) + " DN subtracted, white level " +
                    std::to_string(int(r.meta.white_level_dn)) + " DN");
  return v;
}

}  // namespace

ViewImage load_view_image(const std::filesystem::path& file) {
  if (!std::filesystem::is_regular_file(file)) throw InputError(file.string(), "", "no such file");
  const std::string ext = lower_extension(file);
  if (ext == ".tif" || ext == ".tiff") return load_raw(file);
  if (ext != ".exr") throw InputError(file.string(), "", "expected a spectral EXR, an electrons.exr or a raw.tiff");
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) throw InputError(file.string(), "", "not a readable EXR: " + OIIO::geterror());
  const auto& names = in->spec().channelnames;
  auto has = [&](const char* c) { return std::find(names.begin(), names.end(), c) != names.end(); };
  if (has("R") && has("G") && has("B") && has("mosaic")) return load_electrons(file, *in);
  in->close();
  return load_radiance(file);
}

}  // namespace ofl
