#include "renderer/camera/description/camera_description.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "renderer/core/files/csv.h"
#include "renderer/core/errors/error.h"
#include "renderer/formats/iset_sensor.h"
#include "renderer/formats/mat_file.h"
#include "renderer/spectral/spectrum_json.h"

namespace ofl {

double SensorDescription::dark_current_at_temperature() const {
  return dark_current_e_per_s * std::exp2((temperature_C - dark_reference_C) / dark_doubling_C);
}

int SensorDescription::white_level_dn() const {
  double clipped = std::floor(full_well_e * total_gain() + 0.5) + black_level_dn;
  return static_cast<int>(std::min<double>(clipped, adc_max_dn()));
}

namespace {

uint64_t unsigned_or(const JsonNode& n, const std::string& key, uint64_t def) {
  auto v = n.find(key);
  if (!v) return def;
  if (!v->raw().is_number_integer()) v->fail("expected a non-negative integer");
  if (!v->raw().is_number_unsigned() && v->raw().get<long long>() < 0) v->fail("expected a non-negative integer");
  return v->raw().get<uint64_t>();
}

LensDescription parse_lens(const JsonNode& n) {
  n.check_keys({"f_number", "focal_length_mm", "magnification", "transmittance", "cos4", "sensor_cra_deg"});
  LensDescription l;
  l.f_number = n.number_or("f_number", l.f_number, 0.3, 1000.0);
  if (auto f = n.find("focal_length_mm")) l.focal_length_mm = f->positive();
  if (auto m = n.find("magnification")) {
    l.magnification = m->number(-1e3, 1e3);
    if (l.magnification > 0)
      m->fail("must be <= 0 (a real, inverted image; e.g. -0.1 for a 1:10 reduction); 0 means an object at infinity");
  }
  if (auto t = n.find("transmittance")) l.transmittance = parse_spectrum(*t, SpectrumKind::kTransmittance);
  l.cos4 = n.boolean_or("cos4", l.cos4);
  if (auto c = n.find("sensor_cra_deg")) l.sensor_cra_deg = c->number(0.0, 60.0);
  return l;
}

StackedFilter parse_stacked_filter(const JsonNode& n) {
  if (!n.is_object()) n.fail("expected a filter object");
  StackedFilter sf;
  std::string pos = n.choice_or("position", "front", {"front", "sensor"});
  sf.position = pos == "front" ? FilterPosition::kFrontOfLens : FilterPosition::kAtSensor;
  // parse_filter knows every filter field but not "position"; hand it a copy without it.
  nlohmann::json copy = n.raw();
  copy.erase("position");
  JsonNode inner(&copy, n.file(), n.path());
  if (inner.at("type").string() == "measured" && inner.has("points")) {
    inner.check_keys({"type", "name", "points", "interference", "n_eff"});
    OpticalFilter f;
    f.kind = OpticalFilter::Kind::kMeasured;
    f.name = inner.string_or("name", "measured");
    f.interference = inner.boolean_or("interference", true);
    f.n_eff = inner.number_or("n_eff", 2.0, 1.0, 5.0);
    nlohmann::json pts = {{"type", "points"}, {"points", copy.at("points")}, {"outside", "zero"}};
    JsonNode pn(&pts, n.file(), n.path());
    f.measured = parse_spectrum(pn, SpectrumKind::kTransmittance);
    sf.filter = f;
  } else {
    sf.filter = parse_filter(inner);
  }
  return sf;
}

void parse_qe(const JsonNode& n, SensorDescription& s) {
  if (!n.is_object()) n.fail("expected {\"file\": ..., \"columns\": {...}} or {\"R\": ..., \"G\": ..., \"B\": ...}");
  const char* names[3] = {"R", "G", "B"};
  if (n.has("file")) {
    n.check_keys({"file", "columns", "scale"});
    auto file = n.at("file").existing_file();
    double scale = n.number_or("scale", 1.0, 0.0, 1e6);
    std::array<std::string, 3> cols;
    if (auto c = n.find("columns")) {
      c->check_keys({"R", "G", "B"});
      for (int i = 0; i < 3; ++i) cols[i] = c->at(names[i]).string();
    } else {
      CsvNumeric t = read_spectrum_table(file);  // a CSV or an ISETCam .mat
      if (t.header.size() != 4)
        n.fail("the QE file has " + std::to_string(t.header.size() - 1) +
               " value columns; name the R, G and B columns with \"columns\"");
      for (int i = 0; i < 3; ++i) cols[i] = t.header[i + 1];
    }
    for (int i = 0; i < 3; ++i) {
      nlohmann::json spec = {{"type", "csv"}, {"file", std::filesystem::absolute(file).string()}, {"column", cols[i]}, {"scale", scale}};
      JsonNode sn(&spec, n.file(), n.path() + "/columns/" + names[i]);
      s.qe[i] = parse_spectrum(sn, SpectrumKind::kTransmittance);
    }
    s.qe_source = file.filename().string();
  } else {
    n.check_keys({"R", "G", "B"});
    for (int i = 0; i < 3; ++i) s.qe[i] = parse_spectrum(n.at(names[i]), SpectrumKind::kTransmittance);
    s.qe_source = n.at("R").is_string() ? n.at("R").string() : "inline";
  }
}

SensorDescription parse_sensor(const JsonNode& n) {
  n.check_keys({"pixel_pitch_um", "fill_factor", "cfa", "qe", "exposure_s", "system_gain_dn_per_e",
                "conversion_gain_uV_per_e", "adc_uV_per_dn", "analog_gain", "full_well_e", "read_noise_e",
                "dark_current_e_per_s", "dark_current_reference_C", "temperature_C", "dark_current_doubling_C",
                "dsnu_e", "prnu_percent", "black_level_dn", "bit_depth", "fixed_pattern_seed"});
  SensorDescription s;
  s.pixel_pitch_um = n.at("pixel_pitch_um").number(0.1, 1000.0);
  s.fill_factor = n.number_or("fill_factor", s.fill_factor, 1e-3, 1.0);
  if (auto c = n.find("cfa")) {
    auto p = parse_cfa_name(c->string());
    if (!p) c->fail("unknown CFA pattern \"" + c->string() + "\" (expected RGGB, GRBG, GBRG or BGGR)");
    s.cfa = *p;
  }
  parse_qe(n.at("qe"), s);
  s.exposure_s = n.at("exposure_s").positive();
  bool has_k = n.has("system_gain_dn_per_e");
  bool has_cg = n.has("conversion_gain_uV_per_e") || n.has("adc_uV_per_dn");
  if (has_k && has_cg)
    n.at("system_gain_dn_per_e").fail("give either system_gain_dn_per_e or conversion_gain_uV_per_e with adc_uV_per_dn, not both");
  if (has_k) {
    s.system_gain_dn_per_e = n.at("system_gain_dn_per_e").number(1e-6, 1e4);
  } else if (has_cg) {
    double cg = n.at("conversion_gain_uV_per_e").positive();
    double adc = n.at("adc_uV_per_dn").positive();
    s.system_gain_dn_per_e = cg / adc;
  } else {
    n.fail("missing system_gain_dn_per_e (or conversion_gain_uV_per_e with adc_uV_per_dn)");
  }
  s.analog_gain = n.number_or("analog_gain", s.analog_gain, 1e-3, 1e4);
  s.full_well_e = n.at("full_well_e").number(1.0, 1e9);
  s.read_noise_e = n.number_or("read_noise_e", s.read_noise_e, 0.0, 1e6);
  s.dark_current_e_per_s = n.number_or("dark_current_e_per_s", s.dark_current_e_per_s, 0.0, 1e12);
  s.dark_reference_C = n.number_or("dark_current_reference_C", s.dark_reference_C, -273.15, 500.0);
  s.temperature_C = n.number_or("temperature_C", s.dark_reference_C, -273.15, 500.0);
  s.dark_doubling_C = n.number_or("dark_current_doubling_C", s.dark_doubling_C, 0.1, 1000.0);
  s.dsnu_e = n.number_or("dsnu_e", s.dsnu_e, 0.0, 1e9);
  s.prnu = n.number_or("prnu_percent", 0.0, 0.0, 100.0) / 100.0;
  s.bit_depth = n.integer_or("bit_depth", s.bit_depth, 8, 16);
  s.black_level_dn = n.integer_or("black_level_dn", s.black_level_dn, 0, 65535);
  if (s.black_level_dn >= s.adc_max_dn())
    n.at("black_level_dn").fail("black level " + std::to_string(s.black_level_dn) + " leaves no range below the " +
                                std::to_string(s.bit_depth) + "-bit maximum " + std::to_string(s.adc_max_dn()));
  s.fixed_pattern_seed = unsigned_or(n, "fixed_pattern_seed", s.fixed_pattern_seed);
  return s;
}

void add_sample(std::set<double>& xs, double x) {
  if (std::isfinite(x)) xs.insert(std::round(x * 1e6) / 1e6);
}

}  // namespace

CameraDescription parse_camera(const JsonNode& root) {
  // "format": "oralfluor-camera" + "version", as scene and sweep files; the older "format_version"
  // is still read.
  root.check_keys({"format", "version", "format_version", "name", "description", "lens", "filters", "sensor", "optics", "noise", "seed"});
  if (auto f = root.find("format"); f && f->string() != "oralfluor-camera") f->fail("expected \"oralfluor-camera\"");
  for (const char* key : {"version", "format_version"})
    if (auto v = root.find(key)) {
      int ver = v->integer();
      if (ver != 1) v->fail("unsupported camera format version " + std::to_string(ver) + " (this build reads 1)");
    }
  CameraDescription c;
  c.name = root.string_or("name", c.name);
  if (auto l = root.find("lens")) c.lens = parse_lens(*l);
  if (auto f = root.find("filters")) {
    for (size_t i = 0; i < f->size(); ++i) c.filters.filters.push_back(parse_stacked_filter(f->at(i)));
  }
  c.sensor = parse_sensor(root.at("sensor"));
  if (auto o = root.find("optics")) {
    c.optics = parse_optics(*o);
    if (!(c.lens.focal_length_mm > 0)) o->fail("the optics stage needs lens.focal_length_mm");
    double f = c.lens.focal_length_mm, d = c.optics.focus_distance_mm;
    if (d > 0) {
      if (!(d > f)) o->at("focus_distance_mm").fail("must be beyond the focal length " + std::to_string(f) + " mm");
      if (root.at("lens").has("magnification"))
        o->at("focus_distance_mm").fail("give either lens.magnification or optics.focus_distance_mm, not both");
      c.lens.magnification = -f / (d - f);  // the image distance of the focused object, v = f (1 - m)
    }
  }
  c.noise = root.boolean_or("noise", c.noise);
  c.seed = unsigned_or(root, "seed", c.seed);
  c.source = root.file();
  return c;
}

CameraDescription load_camera(const std::filesystem::path& file) {
  if (is_mat_file(file)) return parse_camera(JsonFile::from(import_iset_sensor(file).camera, file.string()).root());
  JsonFile f = JsonFile::load(file);
  return parse_camera(f.root());
}

nlohmann::json spectrum_to_points_json(const Spectrum& s, double lo, double hi, double step) {
  std::set<double> xs;
  for (double k : s.kinks) add_sample(xs, k);
  // A table that drops to zero outside its range keeps that jump exactly: no samples are added
  // outside it ("outside": "zero" does the rest), so interpolation cannot turn the step into a
  // 1 nm ramp (which moved the reference lines by 1 % under a 385 nm LED at a QE table starting at 380 nm).
  bool zero_below = !s.kinks.empty() && s.eval(s.kinks.front() - 1e-3) == 0.0;
  bool zero_above = !s.kinks.empty() && s.eval(s.kinks.back() + 1e-3) == 0.0;
  double a = std::floor(lo / step) * step, b = std::ceil(hi / step) * step;
  for (double x = a; x <= b + 1e-9; x += step)
    if (!(zero_below && x < s.kinks.front()) && !(zero_above && x > s.kinks.back())) add_sample(xs, x);
  nlohmann::json pts = nlohmann::json::array();
  for (double x : xs) {
    if (!(x > 0)) continue;
    pts.push_back({x, std::clamp(s.eval(x), 0.0, 1.0)});
  }
  return {{"type", "points"}, {"points", pts}, {"outside", "zero"}};
}

nlohmann::json camera_to_json(const CameraDescription& c, double lo, double hi) {
  using nlohmann::json;
  json lens = {{"f_number", c.lens.f_number},
               {"transmittance", spectrum_to_points_json(c.lens.transmittance, lo, hi)},
               {"cos4", c.lens.cos4}};
  if (c.lens.focal_length_mm > 0) lens["focal_length_mm"] = c.lens.focal_length_mm;
  if (!(c.optics.enabled && c.optics.focus_distance_mm > 0)) lens["magnification"] = c.lens.magnification;  // else derived
  if (c.lens.sensor_cra_deg >= 0) lens["sensor_cra_deg"] = c.lens.sensor_cra_deg;
  json filters = json::array();
  for (const auto& sf : c.filters.filters) {
    const OpticalFilter& f = sf.filter;
    json j = {{"name", f.name}, {"interference", f.interference}, {"n_eff", f.n_eff},
              {"position", filter_position_name(sf.position)}};
    switch (f.kind) {
      case OpticalFilter::Kind::kLongpass: j["type"] = "longpass"; break;
      case OpticalFilter::Kind::kShortpass: j["type"] = "shortpass"; break;
      case OpticalFilter::Kind::kBandpass: j["type"] = "bandpass"; j["edge2_nm"] = f.edge2_nm; break;
      case OpticalFilter::Kind::kMeasured: j["type"] = "measured"; break;
    }
    if (f.kind == OpticalFilter::Kind::kMeasured) {
      // Tilted filters are looked up at nm / shift_factor, beyond `hi`; the kinks keep the whole table.
      j["points"] = spectrum_to_points_json(f.measured, lo, hi)["points"];
    } else {
      j["edge_nm"] = f.edge_nm;
      j["width_nm"] = f.width_nm;
      j["od"] = f.od;
      j["peak"] = f.peak;
    }
    filters.push_back(j);
  }
  const SensorDescription& s = c.sensor;
  json qe = json::object();
  for (int i = 0; i < 3; ++i) qe[channel_name(i)] = spectrum_to_points_json(s.qe[i], lo, hi);
  json sensor = {{"pixel_pitch_um", s.pixel_pitch_um},
                 {"fill_factor", s.fill_factor},
                 {"cfa", cfa_name(s.cfa)},
                 {"qe", qe},
                 {"exposure_s", s.exposure_s},
                 {"system_gain_dn_per_e", s.system_gain_dn_per_e},
                 {"analog_gain", s.analog_gain},
                 {"full_well_e", s.full_well_e},
                 {"read_noise_e", s.read_noise_e},
                 {"dark_current_e_per_s", s.dark_current_e_per_s},
                 {"dark_current_reference_C", s.dark_reference_C},
                 {"temperature_C", s.temperature_C},
                 {"dark_current_doubling_C", s.dark_doubling_C},
                 {"dsnu_e", s.dsnu_e},
                 {"prnu_percent", s.prnu * 100.0},
                 {"black_level_dn", s.black_level_dn},
                 {"bit_depth", s.bit_depth},
                 {"fixed_pattern_seed", s.fixed_pattern_seed}};
  json out = {{"format", "oralfluor-camera"}, {"version", 1}, {"name", c.name}, {"description", "QE source: " + s.qe_source},
              {"lens", lens},        {"filters", filters}, {"sensor", sensor},
              {"noise", c.noise},    {"seed", c.seed}};
  if (c.optics.enabled) out["optics"] = optics_to_json(c.optics);
  return out;
}

}  // namespace ofl
