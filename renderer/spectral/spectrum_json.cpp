#include "renderer/spectral/spectrum_json.h"

#include <cmath>
#include <sstream>

#include "renderer/core/errors/error.h"

namespace ofl {

// `node` holds the options (when an object), `file_node` names the CSV.
static Spectrum parse_csv_spectrum(const JsonNode& node, const JsonNode& file_node, SpectrumKind kind) {
  SpectrumCsvOptions o;
  o.outside = kind == SpectrumKind::kReflectance ? Outside::kClamp : Outside::kZero;
  if (node.is_object()) {
    o.column = node.string_or("column", "");
    o.scale = node.number_or("scale", 1.0, 0.0);
    o.clip_negative = node.boolean_or("clip_negative", false);
    std::string out = node.choice_or("outside", o.outside == Outside::kClamp ? "clamp" : "zero", {"zero", "clamp"});
    o.outside = out == "clamp" ? Outside::kClamp : Outside::kZero;
  }
  return file_node.read_file([&](const std::filesystem::path& file) {
    TabulatedSpectrum t = read_spectrum_csv(file, o);
    if (kind != SpectrumKind::kEmission) {
      for (size_t i = 0; i < t.value.size(); ++i)
        if (t.value[i] > 1.0 + 1e-6)
          throw InputError(file.string(), "wavelength " + std::to_string(t.nm[i]) + " nm",
                           "value " + std::to_string(t.value[i]) +
                               " above 1 for a reflectance/transmittance (percent? use \"scale\": 0.01)");
    }
    return table_spectrum(std::move(t), file.filename().string() + (o.column.empty() ? "" : ":" + o.column));
  });
}

Spectrum parse_spectrum(const JsonNode& node, SpectrumKind kind) {
  if (node.is_number()) {
    double v = node.number(0.0, kind == SpectrumKind::kEmission ? 1e300 : 1.0);
    return constant_spectrum(v);
  }
  if (node.is_string()) return parse_csv_spectrum(node, node, kind);
  if (!node.is_object()) node.fail("expected a number, a CSV file name or a spectrum object");
  std::string type = node.at("type").string();
  if (type == "constant") {
    node.check_keys({"type", "value"});
    return constant_spectrum(node.at("value").number(0.0, kind == SpectrumKind::kEmission ? 1e300 : 1.0));
  }
  if (type == "csv") {
    node.check_keys({"type", "file", "column", "scale", "clip_negative", "outside"});
    return parse_csv_spectrum(node, node.at("file"), kind);
  }
  if (type == "points") {
    node.check_keys({"type", "points", "outside"});
    JsonNode pts = node.at("points");
    TabulatedSpectrum t;
    t.outside = kind == SpectrumKind::kReflectance ? Outside::kClamp : Outside::kZero;
    std::string out = node.choice_or("outside", t.outside == Outside::kClamp ? "clamp" : "zero", {"zero", "clamp"});
    t.outside = out == "clamp" ? Outside::kClamp : Outside::kZero;
    for (size_t i = 0; i < pts.size(); ++i) {
      JsonNode p = pts.at(i);
      if (!p.is_array() || p.size() != 2) p.fail("expected [wavelength_nm, value]");
      double wl = p.at(0).positive();
      double v = p.at(1).number(0.0, kind == SpectrumKind::kEmission ? 1e300 : 1.0);
      if (!t.nm.empty() && !(wl > t.nm.back())) p.at(0).fail("wavelengths must increase");
      t.nm.push_back(wl);
      t.value.push_back(v);
    }
    if (t.nm.size() < 2) pts.fail("need at least two points");
    return table_spectrum(std::move(t), "points");
  }
  if (type == "gaussian") {
    node.check_keys({"type", "peak_nm", "fwhm_nm"});
    return gaussian_spectrum(node.at("peak_nm").positive(), node.at("fwhm_nm").positive());
  }
  if (type == "blackbody") {
    node.check_keys({"type", "temperature_K"});
    return blackbody_spectrum(node.at("temperature_K").number(100.0, 1e5));
  }
  if (type == "longpass" || type == "shortpass" || type == "bandpass" || type == "measured")
    return parse_filter(node).at_angle(0.0);
  if (type == "product") {
    node.check_keys({"type", "factors"});
    JsonNode f = node.at("factors");
    std::vector<Spectrum> fs;
    for (size_t i = 0; i < f.size(); ++i) fs.push_back(parse_spectrum(f.at(i), i == 0 ? kind : SpectrumKind::kTransmittance));
    if (fs.empty()) f.fail("needs at least one factor");
    return product_spectrum(fs);
  }
  if (type == "sum") {
    // Terms may carry weights: {"type": "sum", "terms": [<spectrum>, ...], "weights": [1, 0.5]}.
    node.check_keys({"type", "terms", "weights"});
    JsonNode t = node.at("terms");
    std::vector<double> w(t.size(), 1.0);
    if (auto wn = node.find("weights")) {
      if (wn->size() != t.size()) wn->fail("needs one weight per term");
      for (size_t i = 0; i < w.size(); ++i) w[i] = wn->at(i).number(0.0);
    }
    std::vector<Spectrum> ts;
    for (size_t i = 0; i < t.size(); ++i) ts.push_back(scaled_spectrum(parse_spectrum(t.at(i), SpectrumKind::kEmission), w[i]));
    if (ts.empty()) t.fail("needs at least one term");
    Spectrum s = sum_spectrum(ts);
    if (kind != SpectrumKind::kEmission) {
      for (double x = 200; x <= 2000; x += 1)
        if (s.eval(x) > 1.0 + 1e-9) node.fail("sum exceeds 1 at " + std::to_string(int(x)) + " nm for a reflectance/transmittance");
    }
    return s;
  }
  node.at("type").fail("unknown spectrum type \"" + type +
                       "\" (expected constant, csv, points, gaussian, blackbody, longpass, shortpass, "
                       "bandpass, measured, product, sum)");
}

OpticalFilter parse_filter(const JsonNode& node) {
  OpticalFilter f;
  std::string type = node.at("type").string();
  f.name = node.string_or("name", type);
  f.interference = node.boolean_or("interference", true);
  f.n_eff = node.number_or("n_eff", 2.0, 1.0, 5.0);
  if (type == "measured") {
    node.check_keys({"type", "name", "file", "column", "scale", "interference", "n_eff", "outside", "clip_negative"});
    f.kind = OpticalFilter::Kind::kMeasured;
    f.measured = parse_csv_spectrum(node, node.at("file"), SpectrumKind::kTransmittance);
    return f;
  }
  node.check_keys({"type", "name", "edge_nm", "edge2_nm", "width_nm", "od", "peak", "interference", "n_eff"});
  if (type == "longpass") f.kind = OpticalFilter::Kind::kLongpass;
  else if (type == "shortpass") f.kind = OpticalFilter::Kind::kShortpass;
  else if (type == "bandpass") f.kind = OpticalFilter::Kind::kBandpass;
  else node.at("type").fail("unknown filter type \"" + type + "\" (expected longpass, shortpass, bandpass, measured)");
  f.edge_nm = node.at("edge_nm").positive();
  if (f.kind == OpticalFilter::Kind::kBandpass) {
    f.edge2_nm = node.at("edge2_nm").positive();
    if (!(f.edge2_nm > f.edge_nm)) node.at("edge2_nm").fail("must be greater than edge_nm");
  }
  f.width_nm = node.number_or("width_nm", 5.0, 0.01, 500.0);
  f.od = node.number_or("od", 4.0, 0.0, 12.0);
  f.peak = node.number_or("peak", 0.95, 0.0, 1.0);
  return f;
}

void check_tabulated(const JsonNode& node, const std::vector<double>& v, const WavelengthGrid& grid,
                     SpectrumKind kind) {
  for (size_t i = 0; i < v.size(); ++i) {
    std::ostringstream at;
    at << " at " << grid.wavelength(static_cast<int>(i)) << " nm";
    if (!std::isfinite(v[i])) node.fail("spectrum is not finite" + at.str());
    if (v[i] < 0) node.fail("spectrum is negative" + at.str());
    if (kind != SpectrumKind::kEmission && v[i] > 1.0 + 1e-9) node.fail("reflectance/transmittance above 1" + at.str());
  }
}

}  // namespace ofl
