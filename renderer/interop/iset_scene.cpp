#include "renderer/interop/iset_scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include <nlohmann/json.hpp>

#include "renderer/camera/camera_pipeline.h"
#include "renderer/core/errors/error.h"
#include "renderer/spectral/color.h"
#include "renderer/spectral/spectra/spectrum.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {
namespace {

constexpr double kLumensPerWatt = 683.0;  // maximum luminous efficacy (CIE photopic, 555 nm)

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  double hi = v[m];
  if (v.size() % 2) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + m));
}

const std::vector<float>* find_aov(const SpectralImage& img, const std::string& name) {
  auto it = img.aovs.find(name);
  if (it == img.aovs.end() || it->second.size() != size_t(img.width) * img.height) return nullptr;
  return &it->second;
}

// Tangents of the pixel-centre rays of a pinhole with vertical field of view `vfov_deg`.
double ray_cos(const SpectralImage& img, double vfov_deg, int x, int y) {
  double tv = std::tan(0.5 * vfov_deg * kPi / 180.0), th = tv * img.width / img.height;
  double u = (2.0 * (x + 0.5) / img.width - 1.0) * th, v = (1.0 - 2.0 * (y + 0.5) / img.height) * tv;
  return 1.0 / std::sqrt(1.0 + u * u + v * v);
}

// Pixels that see scene geometry (aov.material >= 0), or every pixel when the plane is absent.
std::vector<size_t> geometry_pixels(const SpectralImage& img) {
  std::vector<size_t> px;
  const auto* mat = find_aov(img, "aov.material");
  for (size_t i = 0; i < size_t(img.width) * img.height; ++i)
    if (!mat || (*mat)[i] >= 0) px.push_back(i);
  return px;
}

// Column-major rows x cols x bands photons from the row-major, bands-contiguous radiance.
MatValue photon_cube(const SpectralImage& img, const std::vector<float>& data, double* sum) {
  const size_t H = img.height, W = img.width, B = img.bands();
  std::vector<double> out(H * W * B);
  double s = 0;
  for (size_t b = 0; b < B; ++b) {
    double k = photons_per_joule(img.band_nm[b]);
    for (size_t x = 0; x < W; ++x)
      for (size_t y = 0; y < H; ++y) {
        float q = float(double(data[(y * W + x) * B + b]) * k);  // stored as single, summed as stored
        out[b * H * W + x * H + y] = q;
        s += q;
      }
  }
  if (sum) *sum = s;
  return MatValue::array({H, W, B}, std::move(out), true);
}

MatValue luminance(const SpectralImage& img) {
  const size_t H = img.height, W = img.width, B = img.bands();
  auto lo = img.band_lo(), hi = img.band_hi();
  ColorMatching cmf = cie1931_on_bands(lo, hi);
  std::vector<double> out(H * W);
  for (size_t y = 0; y < H; ++y)
    for (size_t x = 0; x < W; ++x) {
      const float* p = img.pixel(int(x), int(y));
      double Y = 0;
      for (size_t b = 0; b < B; ++b) Y += p[b] * cmf.y[b] * (hi[b] - lo[b]);
      out[x * H + y] = kLumensPerWatt * Y;
    }
  return MatValue::array({H, W}, std::move(out));
}

std::string matlab_field_name(std::string key) {
  if (key.rfind("oralfluor.", 0) == 0) key = key.substr(10);
  for (char& c : key)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  if (key.empty() || !std::isalpha(static_cast<unsigned char>(key[0]))) key = "a" + key;
  return key.substr(0, 63);
}

// The LED spectrum the render recorded, as a table (W sr^-1 nm^-1), or nullopt.
std::optional<TabulatedSpectrum> recorded_led(const SpectralImage& img, std::vector<std::string>& warnings) {
  auto it = img.attributes.find("oralfluor.excitation_spd");
  if (it == img.attributes.end()) return std::nullopt;
  try {
    auto j = nlohmann::json::parse(it->second);
    TabulatedSpectrum t;
    t.nm = j.at("nm").get<std::vector<double>>();
    t.value = j.at("W_per_sr_nm").get<std::vector<double>>();
    bool ok = t.nm.size() == t.value.size() && t.nm.size() >= 2;
    for (size_t i = 1; ok && i < t.nm.size(); ++i) ok = t.nm[i] > t.nm[i - 1];
    for (double v : t.value) ok = ok && v >= 0 && std::isfinite(v);
    if (ok) return t;
  } catch (const std::exception&) {
  }
  warnings.push_back("ignoring oralfluor.excitation_spd (not {\"nm\": [...], \"W_per_sr_nm\": [...]}): no illuminant written");
  return std::nullopt;
}

// scene.illuminant: white-Lambertian radiance at the median LED irradiance (see the header).
void add_illuminant(const SpectralImage& img, const TabulatedSpectrum& led, const std::vector<size_t>& px,
                    IsetScene& s) {
  auto lo = img.band_lo(), hi = img.band_hi();
  Spectrum spd = table_spectrum(led, "LED");
  double total = average(spd, led.nm.front(), led.nm.back()) * (led.nm.back() - led.nm.front());
  if (!(total > 0)) {
    s.warnings.push_back("the recorded LED spectrum is zero: no illuminant written");
    return;
  }
  double inside = average(spd, lo.front(), hi.back()) * (hi.back() - lo.front());
  double outside = std::max(0.0, 1.0 - inside / total);
  if (outside > 0.01) {
    std::ostringstream w;
    w.precision(3);
    w << outside * 100 << " % of the LED power lies outside the image's bands (" << lo.front() << "-" << hi.back()
      << " nm): the ISETCam scene and its illuminant do not carry it (render with output_bands covering the LED)";
    s.warnings.push_back(w.str());
  }
  double irradiance = 1.0;  // W m^-2; relative when the render has no aov.irradiance
  std::string how = "relative: the EXR has no aov.irradiance";
  if (const auto* e = find_aov(img, "aov.irradiance")) {
    std::vector<double> lit;
    for (size_t i : px)
      if ((*e)[i] > 0) lit.push_back((*e)[i]);
    if (!lit.empty()) {
      irradiance = median(lit);
      how = "white Lambertian reflector at the median LED irradiance of the lit pixels";
    }
  }
  std::vector<double> photons;
  for (int b = 0; b < img.bands(); ++b) {
    double e_nm = irradiance * average(spd, lo[b], hi[b]) / total;  // W m^-2 nm^-1
    photons.push_back(float(e_nm / kPi * photons_per_joule(img.band_nm[b])));
  }
  MatValue il = MatValue::structure();
  il.set("name", MatValue::string("oralfluor LEDs"));
  il.set("type", MatValue::string("illuminant"));
  MatValue spec = MatValue::structure();
  spec.set("wave", MatValue::vector(img.band_nm, true));
  il.set("spectrum", spec);
  MatValue data = MatValue::structure();
  MatValue ph = MatValue::vector(photons, true);
  ph.single = true;
  data.set("photons", ph);
  il.set("data", data);
  il.set("comment", MatValue::string("photons s^-1 sr^-1 m^-2 nm^-1; " + how));
  s.scene.set("illuminant", il);
  s.has_illuminant = true;
}

// What ISETCam ignores but `import-iset` restores: every AOV plane (metadata.aov.<name>, rows x
// cols single, as stored) and every header string under its own name (metadata.exrAttributes, the
// EXR's attributes as a JSON object; MATLAB field names cannot hold them all).
void add_restorable_fields(const SpectralImage& img, MatValue& meta) {
  const size_t H = img.height, W = img.width;
  MatValue aov = MatValue::structure();
  for (auto& [name, plane] : img.aovs) {
    if (plane.size() != H * W) continue;
    std::vector<double> cm(H * W);
    for (size_t x = 0; x < W; ++x)
      for (size_t y = 0; y < H; ++y) cm[x * H + y] = plane[y * W + x];
    aov.set(matlab_field_name(name.rfind("aov.", 0) == 0 ? name.substr(4) : name), MatValue::array({H, W}, std::move(cm), true));
  }
  if (!aov.fields.empty()) meta.set("aov", aov);
  nlohmann::json attrs = nlohmann::json::object();
  for (auto& [k, v] : img.attributes) attrs[k] = v;
  // EXR text attributes are bytes; JSON is UTF-8. Bytes that are not UTF-8 (a Latin-1 description
  // from another tool) become U+FFFD in this copy; the radiance is not touched.
  meta.set("exrAttributes", MatValue::string(attrs.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)));
}

void resolve_geometry(const SpectralImage& img, const IsetSceneOptions& opt, const std::string& source,
                      const std::vector<size_t>& px, IsetScene& s) {
  std::optional<double> vfov = render_vfov_deg(img, &s.warnings);
  if (opt.hfov_deg) {
    s.hfov_deg = *opt.hfov_deg;
    s.fov_source = "given";
  } else if (vfov) {
    s.hfov_deg = 2.0 * std::atan(std::tan(0.5 * *vfov * kPi / 180.0) * img.width / img.height) * 180.0 / kPi;
    s.fov_source = "oralfluor.vfov_deg";
  } else {
    throw InputError(source, "oralfluor.vfov_deg", "the EXR does not record its field of view: give it (--hfov)");
  }
  if (opt.distance_m) {
    s.distance_m = *opt.distance_m;
    s.distance_source = "given";
    return;
  }
  const auto* depth = find_aov(img, "aov.depth");
  if (!depth || !vfov || px.empty())
    throw InputError(source, "aov.depth", "the EXR has no depth of scene geometry: give the scene distance (--distance)");
  std::vector<double> z;
  for (size_t i : px) {
    double t = (*depth)[i];
    if (t > 0 && std::isfinite(t)) z.push_back(t * ray_cos(img, *vfov, int(i % img.width), int(i / img.width)));
  }
  if (z.empty()) throw InputError(source, "aov.depth", "no pixel sees geometry: give the scene distance (--distance)");
  s.distance_m = median(z);
  s.distance_source = "median depth of the pixels that see geometry (aov.depth)";
}

}  // namespace

IsetScene make_iset_scene(const SpectralImage& img, const IsetSceneOptions& opt, const std::string& source) {
  if (img.width <= 0 || img.height <= 0 || img.bands() == 0) throw InputError(source, "", "empty spectral image");
  IsetScene s;
  std::vector<size_t> px = geometry_pixels(img);
  resolve_geometry(img, opt, source, px, s);
  MatValue& sc = s.scene = MatValue::structure();
  sc.set("type", MatValue::string("scene"));
  std::string name = opt.name.empty() ? std::filesystem::path(source).stem().string() : opt.name;
  sc.set("name", MatValue::string(name));
  MatValue spec = MatValue::structure();
  spec.set("wave", MatValue::vector(img.band_nm, true));
  sc.set("spectrum", spec);
  sc.set("distance", MatValue::scalar(s.distance_m));
  sc.set("magnification", MatValue::scalar(1.0));
  sc.set("wAngular", MatValue::scalar(s.hfov_deg));
  MatValue data = MatValue::structure();
  data.set("photons", photon_cube(img, img.data, &s.photon_sum));
  data.set("bitDepth", MatValue::scalar(32));
  data.set("luminance", luminance(img));
  sc.set("data", data);
  if (auto led = recorded_led(img, s.warnings)) add_illuminant(img, *led, px, s);
  MatValue meta = MatValue::structure();
  meta.set("source", MatValue::string(source));
  meta.set("units", MatValue::string("data.photons: photons s^-1 sr^-1 m^-2 nm^-1 (from W sr^-1 m^-2 nm^-1)"));
  meta.set("distanceSource", MatValue::string(s.distance_source));
  for (auto& [k, v] : img.attributes)
    if (k.rfind("oralfluor.", 0) == 0) meta.set(matlab_field_name(k), MatValue::string(v));
  if (!img.fluorescence.empty()) meta.set("fluorescencePhotons", photon_cube(img, img.fluorescence, nullptr));
  add_restorable_fields(img, meta);
  sc.set("metadata", meta);
  return s;
}

void write_iset_scene(const std::filesystem::path& file, const IsetScene& s) { write_mat_file(file, {{"scene", s.scene}}); }

// ---- import ---------------------------------------------------------------------------------

namespace {

const MatValue& find_scene_struct(const std::string& file, const MatVariables& vars) {
  const MatValue* found = nullptr;
  for (auto& [name, v] : vars)
    if (name == "scene" && v.kind == MatValue::Kind::kStruct) return v;
  for (auto& [name, v] : vars) {
    const MatValue* t = v.field("type");
    if (v.kind == MatValue::Kind::kStruct && t && t->kind == MatValue::Kind::kText && t->text == "scene") {
      if (found) throw InputError(file, "variable \"scene\"", "several scene structs and none named scene");
      found = &v;
    }
  }
  if (!found) throw InputError(file, "variable \"scene\"", "missing: no ISETCam scene struct in the file");
  return *found;
}

// Radiance (row-major, bands contiguous) from a column-major rows x cols x bands photon array.
std::vector<float> radiance_from_photons(const std::string& file, const std::string& where, const MatValue& v,
                                         const std::vector<double>& wave, size_t H, size_t W) {
  std::vector<double> q = mat_numbers(file, v, where);
  std::vector<size_t> d = v.dims;
  if (d.size() == 2) d.push_back(1);
  const size_t B = wave.size();
  if (d.size() != 3 || d[0] != H || d[1] != W || d[2] != B)
    throw InputError(file, where, "expected " + std::to_string(H) + " x " + std::to_string(W) + " x " + std::to_string(B) +
                                      " (rows x cols x wavelengths)");
  std::vector<float> out(H * W * B);
  for (size_t b = 0; b < B; ++b) {
    double k = photon_energy_J(wave[b]);
    for (size_t x = 0; x < W; ++x)
      for (size_t y = 0; y < H; ++y) {
        double p = q[b * H * W + x * H + y];
        if (p < 0) throw InputError(file, where, "negative radiance");
        out[(y * W + x) * B + b] = float(p * k);
      }
  }
  return out;
}

// The fields export-iset adds for oralfluor (see add_restorable_fields): the fluorescence layer,
// the AOV planes and the EXR's header strings.
void restore_oralfluor_fields(const std::string& file, const MatValue& meta, const std::vector<double>& wave, size_t H,
                              size_t W, SpectralImage& img) {
  if (const MatValue* f = meta.field("fluorescencePhotons"))
    img.fluorescence = radiance_from_photons(file, "scene.metadata.fluorescencePhotons", *f, wave, H, W);
  if (const MatValue* aov = meta.field("aov"); aov && aov->kind == MatValue::Kind::kStruct)
    for (auto& [name, v] : aov->fields) {
      const std::string where = "scene.metadata.aov." + name;
      std::vector<double> p = mat_numbers(file, v, where);
      if (v.dims.size() != 2 || v.dims[0] != H || v.dims[1] != W)
        throw InputError(file, where, "expected " + std::to_string(H) + " x " + std::to_string(W) + " (the photons' rows x cols)");
      std::vector<float>& plane = img.aovs["aov." + name];
      plane.resize(H * W);
      for (size_t x = 0; x < W; ++x)
        for (size_t y = 0; y < H; ++y) plane[y * W + x] = float(p[x * H + y]);
    }
  if (const MatValue* a = meta.field("exrAttributes"); a && a->kind == MatValue::Kind::kText) {
    nlohmann::json j = nlohmann::json::parse(a->text, nullptr, false);
    if (!j.is_object()) throw InputError(file, "scene.metadata.exrAttributes", "expected a JSON object of header strings");
    for (auto& [k, v] : j.items()) {
      if (!v.is_string()) throw InputError(file, "scene.metadata.exrAttributes", "attribute \"" + printable(k) + "\" is not a string");
      img.attributes[k] = v.get<std::string>();
    }
    img.attributes["oralfluor.iset_source"] = file;
  }
}

}  // namespace

SpectralImage read_iset_scene(const std::filesystem::path& path) {
  const std::string file = path.string();
  MatVariables vars = read_mat_file(path);
  const MatValue& sc = find_scene_struct(file, vars);
  std::vector<double> wave = mat_numbers(file, mat_require(file, sc, "scene", "spectrum.wave"), "scene.spectrum.wave");
  for (size_t i = 1; i < wave.size(); ++i)
    if (!(wave[i] > wave[i - 1])) throw InputError(file, "scene.spectrum.wave", "wavelengths must increase");
  if (wave.empty()) throw InputError(file, "scene.spectrum.wave", "no wavelengths");
  const MatValue& ph = mat_require(file, sc, "scene", "data.photons");
  std::vector<size_t> d = ph.dims;
  if (d.size() == 2) d.push_back(1);
  if (d.size() != 3 || d[2] != wave.size())
    throw InputError(file, "scene.data.photons", "expected rows x cols x " + std::to_string(wave.size()) + " (one plane per wavelength)");
  const size_t H = d[0], W = d[1];
  if (H < 1 || W < 1 || H > 65536 || W > 65536) throw InputError(file, "scene.data.photons", "expected 1 to 65536 rows and columns");
  SpectralImage img;
  img.width = int(W);
  img.height = int(H);
  img.band_nm = wave;
  img.data = radiance_from_photons(file, "scene.data.photons", ph, wave, H, W);
  img.attributes["emissiveUnits"] = "W.m^-2.sr^-1";
  img.attributes["oralfluor.scene"] = file;
  if (const MatValue* meta = sc.field("metadata"); meta && meta->kind == MatValue::Kind::kStruct)
    restore_oralfluor_fields(file, *meta, wave, H, W, img);
  if (const MatValue* w = sc.field("wAngular")) {
    double h = mat_scalar(file, *w, "scene.wAngular");
    if (!(h > 0 && h < 180)) throw InputError(file, "scene.wAngular", "expected a field of view in (0, 180) degrees");
    double v = 2.0 * std::atan(std::tan(0.5 * h * kPi / 180.0) * double(H) / double(W)) * 180.0 / kPi;
    // A restored render header keeps its own text unless wAngular was changed since.
    auto it = img.attributes.find("oralfluor.vfov_deg");
    double kept = it == img.attributes.end() ? -1.0 : std::strtod(it->second.c_str(), nullptr);
    if (!(std::abs(kept - v) <= 1e-9 * v)) {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.17g", v);
      img.attributes["oralfluor.vfov_deg"] = buf;
    }
  }
  if (const MatValue* dist = sc.field("distance"))
    img.attributes["oralfluor.iset_distance_m"] = std::to_string(mat_scalar(file, *dist, "scene.distance"));
  return img;
}

}  // namespace ofl
