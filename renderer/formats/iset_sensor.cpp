#include "renderer/formats/iset_sensor.h"

#include <array>
#include <cctype>
#include <cmath>
#include <sstream>

#include "renderer/core/errors/error.h"
#include "renderer/formats/mat_file.h"

namespace ofl {
namespace {

constexpr double kDefaultExposure = 0.01;

struct SensorReader {
  std::string file;
  const MatValue& s;

  const MatValue* find(const std::string& path) const { return mat_find(s, path); }
  const MatValue& require(const std::string& path) const { return mat_require(file, s, "sensor", path); }
  std::vector<double> numbers(const std::string& path) const { return mat_numbers(file, require(path), "sensor." + path); }
  double scalar(const std::string& path) const { return mat_scalar(file, require(path), "sensor." + path); }
  double scalar_or(const std::string& path, double def) const {
    const MatValue* v = find(path);
    if (!v || (v->kind == MatValue::Kind::kNumeric && v->numbers.empty()) || v->kind == MatValue::Kind::kEmpty) return def;
    return mat_scalar(file, *v, "sensor." + path);
  }
  [[noreturn]] void fail(const std::string& path, const std::string& what) const { throw InputError(file, "sensor." + path, what); }
};

const MatValue& find_sensor(const std::string& file, const MatVariables& vars) {
  for (auto& [name, v] : vars)
    if (name == "sensor" && v.kind == MatValue::Kind::kStruct) return v;
  const MatValue* found = nullptr;
  std::string names;
  for (auto& [name, v] : vars) {
    names += (names.empty() ? "" : ", ") + name;
    const MatValue* t = v.field("type");
    if (v.kind == MatValue::Kind::kStruct && t && t->kind == MatValue::Kind::kText && t->text == "sensor") found = &v;
  }
  if (!found)
    throw InputError(file, "variable \"sensor\"", "missing: no ISETCam sensor struct in the file (variables: " +
                                                      (names.empty() ? std::string("none") : names) + ")");
  return *found;
}

// Index (0 R, 1 G, 2 B) of each ISETCam filter, from the first letter of its name.
std::vector<int> rgb_of_filters(const SensorReader& r, size_t k) {
  const MatValue& names = r.require("color.filterNames");
  if (names.kind != MatValue::Kind::kCell || names.cells.size() != k)
    r.fail("color.filterNames", "expected a cell of " + std::to_string(k) + " names (one per column of filterSpectra)");
  std::vector<int> rgb;
  std::string all;
  for (auto& c : names.cells) {
    std::string n = c.kind == MatValue::Kind::kText ? c.text : "?";
    all += (all.empty() ? "" : ", ") + n;
    char f = n.empty() ? '?' : char(std::tolower(static_cast<unsigned char>(n[0])));
    rgb.push_back(f == 'r' ? 0 : f == 'g' ? 1 : f == 'b' ? 2 : -1);
  }
  std::array<int, 3> count = {0, 0, 0};
  for (int i : rgb)
    if (i >= 0) ++count[i];
  if (k != 3 || count[0] != 1 || count[1] != 1 || count[2] != 1)
    r.fail("color.filterNames", "oralfluor models RGB sensors: need one r, one g and one b filter (this sensor has: " + all + ")");
  return rgb;
}

// The 2x2 CFA cell as "RGGB"-style letters (top-left, top-right, bottom-left, bottom-right).
std::string cfa_name(const SensorReader& r, const std::vector<int>& rgb) {
  const MatValue& p = r.require("cfa.pattern");
  std::vector<double> idx = mat_numbers(r.file, p, "sensor.cfa.pattern");
  if (p.dims.size() != 2 || p.dims[0] % 2 || p.dims[1] % 2 || idx.empty())
    r.fail("cfa.pattern", "expected a 2x2 (or repeating 2x2) matrix of filter indices");
  const size_t rows = p.dims[0], cols = p.dims[1];
  auto at = [&](size_t y, size_t x) { return idx[x * rows + y]; };
  for (size_t y = 0; y < rows; ++y)
    for (size_t x = 0; x < cols; ++x)
      if (at(y, x) != at(y % 2, x % 2)) r.fail("cfa.pattern", "oralfluor models 2x2 Bayer cells; this pattern does not repeat one");
  const char letters[3] = {'R', 'G', 'B'};
  std::string s;
  const std::pair<size_t, size_t> cell[4] = {{0, 0}, {0, 1}, {1, 0}, {1, 1}};  // row by row
  for (auto [y, x] : cell) {
    double v = at(y, x);
    if (v != std::floor(v) || v < 1 || v > double(rgb.size())) r.fail("cfa.pattern", "entries must be filter indices 1.." + std::to_string(rgb.size()));
    s += letters[rgb[size_t(v) - 1]];
  }
  if (s != "RGGB" && s != "GRBG" && s != "GBRG" && s != "BGGR")
    r.fail("cfa.pattern", "the 2x2 cell " + s + " is not a Bayer pattern (RGGB, GRBG, GBRG, BGGR)");
  return s;
}

// A spectrum over `wave` from a vector of N values or a scalar (ISETCam allows both for the pixel QE).
std::vector<double> per_wave(const SensorReader& r, const std::string& path, size_t n) {
  std::vector<double> v = r.numbers(path);
  if (v.size() == 1) return std::vector<double>(n, v[0]);
  if (v.size() < n) r.fail(path, "has " + std::to_string(v.size()) + " values for " + std::to_string(n) + " wavelengths");
  v.resize(n);  // an irFilter matrix for several field heights: its first (on-axis) column
  return v;
}

nlohmann::json qe_points(const std::vector<double>& wave, const std::vector<double>& qe) {
  nlohmann::json pts = nlohmann::json::array();
  for (size_t i = 0; i < wave.size(); ++i) pts.push_back({wave[i], qe[i]});
  return {{"type", "points"}, {"points", pts}, {"outside", "zero"}};
}

nlohmann::json spectral_qe(const SensorReader& r, const std::vector<int>& rgb, std::vector<std::string>& notes) {
  std::vector<double> wave = r.numbers("spectrum.wave");
  const size_t n = wave.size();
  if (n < 2) r.fail("spectrum.wave", "needs at least two wavelengths");
  for (size_t i = 1; i < n; ++i)
    if (!(wave[i] > wave[i - 1])) r.fail("spectrum.wave", "wavelengths must increase");
  const MatValue& fs = r.require("color.filterSpectra");
  std::vector<double> f = mat_numbers(r.file, fs, "sensor.color.filterSpectra");
  if (fs.dims.size() != 2 || fs.dims[0] != n || fs.dims[1] != rgb.size())
    r.fail("color.filterSpectra", "expected " + std::to_string(n) + " x " + std::to_string(rgb.size()) + " (wavelengths x filters)");
  std::vector<double> ir(n, 1.0), pd(n, 1.0);
  if (r.find("color.irFilter") && !r.require("color.irFilter").numbers.empty()) ir = per_wave(r, "color.irFilter", n);
  else notes.push_back("no color.irFilter: taken as 1");
  if (r.find("pixel.spectralQE")) pd = per_wave(r, "pixel.spectralQE", n);
  else notes.push_back("no pixel.spectralQE: photodetector QE taken as 1");
  nlohmann::json qe = nlohmann::json::object();
  const char* names[3] = {"R", "G", "B"};
  for (size_t k = 0; k < rgb.size(); ++k) {
    std::vector<double> q(n);
    for (size_t i = 0; i < n; ++i) {
      q[i] = f[k * n + i] * ir[i] * pd[i];
      if (q[i] < 0 || q[i] > 1.0 + 1e-9)
        r.fail("color.filterSpectra", "spectral QE " + std::to_string(q[i]) + " at " + std::to_string(wave[i]) + " nm is outside 0..1");
    }
    qe[names[rgb[k]]] = qe_points(wave, q);
  }
  return qe;
}

// Volt-domain pixel and readout parameters in electrons and DN.
void electrical(const SensorReader& r, nlohmann::json& sensor, std::vector<std::string>& notes) {
  double cg = r.scalar("pixel.conversionGain");
  if (!(cg > 0)) r.fail("pixel.conversionGain", "must be > 0 (volts per electron)");
  double swing = r.scalar("pixel.voltageSwing");
  if (!(swing > 0)) r.fail("pixel.voltageSwing", "must be > 0 (volts)");
  sensor["full_well_e"] = swing / cg;
  sensor["read_noise_e"] = std::max(0.0, r.scalar_or("pixel.readNoise", 0.0)) / cg;
  sensor["dark_current_e_per_s"] = std::max(0.0, r.scalar_or("pixel.darkVoltage", 0.0)) / cg;
  sensor["dsnu_e"] = std::max(0.0, r.scalar_or("sigmaOffsetFPN", 0.0)) / cg;
  sensor["prnu_percent"] = std::max(0.0, r.scalar_or("sigmaGainFPN", 0.0));
  std::string method = "linear";
  if (const MatValue* m = r.find("quantization.method"); m && m->kind == MatValue::Kind::kText) method = m->text;
  double bits = r.scalar_or("quantization.bits", 0.0);
  if (method == "analog" || bits == 0) {
    bits = 16;
    notes.push_back("analog (unquantised) ISETCam sensor: a 16-bit ADC over the voltage swing is assumed");
  }
  if (bits != std::floor(bits) || bits < 8 || bits > 16) r.fail("quantization.bits", "oralfluor models 8- to 16-bit ADCs");
  double step = swing / std::pow(2.0, bits);  // volts per DN
  double ag = r.scalar_or("analogGain", 1.0), ao = r.scalar_or("analogOffset", 0.0);
  if (!(ag > 0)) r.fail("analogGain", "must be > 0");
  sensor["bit_depth"] = int(bits);
  sensor["system_gain_dn_per_e"] = cg / step;
  sensor["analog_gain"] = 1.0 / ag;
  sensor["black_level_dn"] = int(std::lround(std::max(0.0, ao) / ag / step));
}

void geometry(const SensorReader& r, nlohmann::json& sensor, std::vector<std::string>& notes) {
  double w = r.scalar("pixel.width"), h = r.scalar_or("pixel.height", w);
  double wg = r.scalar_or("pixel.widthGap", 0.0), hg = r.scalar_or("pixel.heightGap", 0.0);
  double dx = w + wg, dy = h + hg;
  if (!(dx > 0)) r.fail("pixel.width", "must be > 0 (metres)");
  if (std::fabs(dy - dx) > 1e-3 * dx) r.fail("pixel.height", "oralfluor models square pixels (width + gap = height + gap)");
  sensor["pixel_pitch_um"] = dx * 1e6;
  double pw = r.scalar_or("pixel.pdWidth", w), ph = r.scalar_or("pixel.pdHeight", h);
  double ff = pw * ph / (dx * dy);
  if (!(ff > 0)) r.fail("pixel.pdWidth", "photodetector area must be > 0");
  if (ff > 1.0 + 1e-9) r.fail("pixel.pdWidth", "photodetector larger than the pixel");
  sensor["fill_factor"] = std::min(1.0, ff);
  double rows = r.scalar_or("rows", 0), cols = r.scalar_or("cols", 0);
  if (rows > 0 && cols > 0) {
    std::ostringstream s;
    s << "sensor size " << rows << " x " << cols << " pixels not imported: the camera works on the radiance image's grid";
    notes.push_back(s.str());
  }
}

}  // namespace

IsetSensorImport import_iset_sensor(const std::filesystem::path& path) {
  const std::string file = path.string();
  MatVariables vars = read_mat_file(path);
  SensorReader r{file, find_sensor(file, vars)};
  IsetSensorImport out;
  auto& notes = out.notes;
  std::string name = path.stem().string();
  if (const MatValue* n = r.find("name"); n && n->kind == MatValue::Kind::kText && !n->text.empty()) name = n->text;

  const MatValue& fs = r.require("color.filterSpectra");
  std::vector<int> rgb = rgb_of_filters(r, fs.dims.size() == 2 ? fs.dims[1] : 0);
  nlohmann::json sensor = nlohmann::json::object();
  geometry(r, sensor, notes);
  sensor["cfa"] = cfa_name(r, rgb);
  sensor["qe"] = spectral_qe(r, rgb, notes);
  electrical(r, sensor, notes);

  double t = r.scalar_or("integrationTime", 0.0);
  bool ae = r.scalar_or("AE", 0.0) != 0;
  if (!(t > 0) || ae) {
    t = kDefaultExposure;
    notes.push_back("ISETCam auto exposure (integrationTime 0 or AE on): exposure_s set to 0.01 s; set it in the camera file");
  }
  sensor["exposure_s"] = t;
  int flag = int(r.scalar_or("noiseFlag", 2));
  if (flag == 1) {
    for (const char* k : {"read_noise_e", "dark_current_e_per_s", "dsnu_e", "prnu_percent"}) sensor[k] = 0.0;
    notes.push_back("noiseFlag 1 (shot noise only): read noise, dark current, DSNU and PRNU set to 0");
  }
  notes.push_back("ISETCam keeps the optics in the optical image, not the sensor: the lens is oralfluor's default (f/2.8, T = 1, cos^4); edit \"lens\"");
  out.camera = {{"format", "oralfluor-camera"}, {"version", 1},
                {"name", name},
                {"description", "imported from the ISETCam sensor " + file},
                {"lens", nlohmann::json::object()},
                {"filters", nlohmann::json::array()},
                {"sensor", sensor},
                {"noise", flag != 0},
                {"seed", 1}};
  return out;
}

}  // namespace ofl
