#include "renderer/diagnose/diagnose_model.h"

#include <cmath>
#include <cstdio>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/spectral/spectrum_json.h"

namespace ofl {

namespace {

std::string cell_text(const JsonNode& n) {
  if (n.is_string()) return n.string();
  if (n.is_number()) {
    double v = n.number();
    char b[64];
    std::snprintf(b, sizeof b, "%.15g", v);
    return b;
  }
  n.fail("expected a string or a number");
}

std::vector<std::string> strings(const JsonNode& n) {
  std::vector<std::string> v;
  if (n.is_string()) return {n.string()};
  for (size_t i = 0; i < n.size(); ++i) v.push_back(n.at(i).string());
  return v;
}

std::vector<RowFilter> parse_select(const JsonNode& n) {
  std::vector<RowFilter> out;
  for (auto& k : n.keys()) {
    JsonNode v = n.at(k);
    RowFilter f;
    f.column = k;
    if (v.is_array())
      for (size_t i = 0; i < v.size(); ++i) f.values.push_back(cell_text(v.at(i)));
    else
      f.values.push_back(cell_text(v));
    out.push_back(f);
  }
  return out;
}

// true/false, or an object of options for the candidate.
bool candidate_on(const JsonNode& c, const char* key, std::optional<JsonNode>* options = nullptr) {
  auto n = c.find(key);
  if (!n) return true;
  if (n->raw().is_boolean()) return n->boolean();
  if (!n->is_object()) n->fail("expected true, false or an object of options");
  if (options) *options = *n;
  return n->boolean_or("enabled", true);
}

void parse_selection(const JsonNode& r, DiagnoseModelFile& m) {
  if (auto g = r.find("groups")) m.selection.group_columns = strings(*g);
  if (auto g = r.find("replicates")) m.selection.replicate_columns = strings(*g);
  m.selection.report_by = r.string_or("report_by", "");
  if (auto s = r.find("selection")) {
    s->check_keys({"z", "max_causes", "min_fold_fraction", "min_effect_to_noise", "subset_columns", "check_by"});
    if (auto sc = s->find("subset_columns")) m.selection.subset_columns = strings(*sc);
    m.selection.check_by = s->string_or("check_by", m.selection.check_by);
    m.selection.z = s->number_or("z", m.selection.z, 0.0, 100.0);
    m.selection.max_causes = s->integer_or("max_causes", m.selection.max_causes, 0, 100);
    m.selection.min_fold_fraction = s->number_or("min_fold_fraction", m.selection.min_fold_fraction, 0.0, 0.99);
    m.selection.min_effect_to_noise = s->number_or("min_effect_to_noise", m.selection.min_effect_to_noise, 0.0, 10.0);
  }
}

// The model is evaluated on its grid and interpolated linearly to the recorded wavelengths; across
// an analytic long-pass edge steeper than the grid, that interpolation misplaces the edge (20 % at
// 3.5 nm below a 5 nm-wide edge on a 2 nm grid), and the fit then moves emission shifts (+0.5 nm)
// and offsets (a third) to make up for it; the leaked excitation light (LED times the blocked
// fraction) needs half the edge's scale (docs/diagnose.md, "Model grid").
void warn_if_grid_misses_the_edge(const JsonNode& r, const SpectraModel& s) {
  if (!s.emission_filter || s.emission_filter->kind == OpticalFilter::Kind::kMeasured) return;
  const double scale = s.emission_filter->width_nm / (2.0 * std::log(9.0));  // the logistic's scale
  if (s.grid_step_nm > 0.5 * scale * 1.0001)
    std::fprintf(stderr,
                 "warning: %s: /grid_step_nm: %g nm is coarser than the emission filter's edge (10-90 %% over %g nm, "
                 "scale %.2f nm): the edge is interpolated with errors that bias shifts, offsets and leaks; use %.2g nm or less\n",
                 r.file().c_str(), s.grid_step_nm, s.emission_filter->width_nm, scale, 0.5 * scale);
}

void parse_spectra(const JsonNode& r, DiagnoseModelFile& m) {
  r.check_keys({"format", "kind", "description", "select", "file_column", "groups", "replicates", "report_by", "selection",
                "fit_range_nm", "grid_step_nm", "instrument_fwhm_nm", "fluorophores", "lights", "excitation_filter",
                "emission_filter", "leak", "candidates", "plausible", "layered_tissue", "shared_concentrations", "tissue_per",
                "instrument_column"});
  SpectraModel& s = m.spectra;
  s.base_dir = std::filesystem::path(m.file).parent_path();
  m.file_column = r.string_or("file_column", "csv");
  if (auto f = r.find("fit_range_nm")) {
    auto v = f->numbers();
    if (v.size() != 2 || !(v[1] > v[0])) f->fail("expected [min_nm, max_nm] with min < max");
    s.fit_min_nm = v[0];
    s.fit_max_nm = v[1];
  }
  s.grid_step_nm = r.number_or("grid_step_nm", 0.5, 0.1, 50.0);
  s.instrument_fwhm_nm = r.number_or("instrument_fwhm_nm", 0.0, 0.0, 100.0);
  if (auto f = r.find("fluorophores")) s.fluorophores = strings(*f);
  JsonNode L = r.at("lights");
  L.check_keys({"nearest", "floor_fraction", "entries"});
  s.nearest_column = L.string_or("nearest", "");
  s.light_floor_fraction = L.number_or("floor_fraction", 1e-3, 0.0, 0.5);
  JsonNode E = L.at("entries");
  if (E.size() == 0) E.fail("no light entries");
  for (size_t i = 0; i < E.size(); ++i) {
    JsonNode e = E.at(i);
    e.check_keys({"name", "when", "spectrum", "leak"});
    LightEntry le;
    le.name = e.string_or("name", "light " + std::to_string(i));
    JsonNode w = e.at("when");
    for (auto& k : w.keys()) le.when[k] = cell_text(w.at(k));
    le.spectrum = parse_spectrum(e.at("spectrum"), SpectrumKind::kEmission);
    if (auto lk = e.find("leak")) le.leak = parse_spectrum(*lk, SpectrumKind::kEmission);
    s.lights.push_back(std::move(le));
  }
  if (auto f = r.find("excitation_filter")) s.excitation_filter = parse_filter(*f);
  if (auto f = r.find("emission_filter")) s.emission_filter = parse_filter(*f);
  warn_if_grid_misses_the_edge(r, s);
  std::string leak = r.choice_or("leak", "computed", {"measured", "computed", "none"});
  s.leak = leak == "measured" ? LeakSource::kMeasured : leak == "none" ? LeakSource::kNone : LeakSource::kComputed;
  if (s.leak == LeakSource::kMeasured)
    for (size_t i = 0; i < s.lights.size(); ++i)
      if (!s.lights[i].leak) E.at(i).fail("\"leak\": \"measured\" needs a \"leak\" spectrum for every light");
  if (auto c = r.find("candidates")) {
    c->check_keys({"blood_absorption", "extra_fluorophore", "wavelength_shift", "bandwidth", "emission_broadening", "stray_light",
                   "longpass_leak", "longpass_edge", "emission_shift", "fluorophore_shape", "second_band", "unknown_band",
                   "instrument_response"});
    auto& o = s.candidates;
    std::optional<JsonNode> bo, eo;
    o.blood = candidate_on(*c, "blood_absorption", &bo);
    if (bo) {
      bo->check_keys({"enabled", "excitation_path_factor"});
      o.blood_excitation_path_factor = bo->number_or("excitation_path_factor", 0.0, 0.0, 10.0);
    }
    o.extra_fluorophore = candidate_on(*c, "extra_fluorophore", &eo);
    if (eo) {
      eo->check_keys({"enabled", "from"});
      if (auto f = eo->find("from")) o.extra_from = strings(*f);
    }
    o.shift = candidate_on(*c, "wavelength_shift");
    o.bandwidth = candidate_on(*c, "bandwidth");
    o.broadening = candidate_on(*c, "emission_broadening");
    o.stray = candidate_on(*c, "stray_light");
    o.leak = candidate_on(*c, "longpass_leak");
    o.edge = candidate_on(*c, "longpass_edge");
    o.emission_shift = candidate_on(*c, "emission_shift");
    o.fluorophore_shape = candidate_on(*c, "fluorophore_shape");
    o.second_band = candidate_on(*c, "second_band");
    o.unknown_band = candidate_on(*c, "unknown_band");
    o.instrument_response = candidate_on(*c, "instrument_response");
  }
  if (auto l = r.find("layered_tissue")) s.layered = parse_layered_cause(*l);
  if (auto sc = r.find("shared_concentrations")) s.shared_by = strings(*sc);
  if (auto tp = r.find("tissue_per")) s.tissue_per = strings(*tp);
  s.instrument_column = r.string_or("instrument_column", "");
  if (auto pl = r.find("plausible")) {
    // {"stray_light": {"fraction": [0, 0.02]}, "extra_fluorophore:teeth": {"mean_fraction": [0.005, 0.05]}}
    for (auto& cand : pl->keys()) {
      JsonNode q = pl->at(cand);
      if (!q.is_object()) q.fail("expected {quantity: [min, max]}");
      for (auto& name : q.keys()) {
        auto v = q.at(name).numbers();
        if (v.size() != 2 || !(v[1] >= v[0])) q.at(name).fail("expected [min, max] with min <= max");
        s.candidates.plausible.push_back({cand, name, v[0], v[1]});
      }
    }
  }
}

void parse_camera(const JsonNode& r, DiagnoseModelFile& m) {
  r.check_keys({"format", "kind", "description", "select", "groups", "replicates", "report_by", "selection", "sensor",
                "grid_step_nm", "nir_cut_nm", "candidates"});
  CameraModel& c = m.camera;
  c.grid_step_nm = r.number_or("grid_step_nm", 4.0, 0.1, 50.0);
  c.nir_cut_nm = r.number_or("nir_cut_nm", 0.0, 0.0, 5000.0);
  JsonNode s = r.at("sensor");
  s.check_keys({"qe", "filters", "black_level"});
  JsonNode q = s.at("qe");
  q.check_keys({"r", "g", "b"});
  c.qe[0] = parse_spectrum(q.at("r"), SpectrumKind::kTransmittance);
  c.qe[1] = parse_spectrum(q.at("g"), SpectrumKind::kTransmittance);
  c.qe[2] = parse_spectrum(q.at("b"), SpectrumKind::kTransmittance);
  if (auto f = s.find("filters"))
    for (size_t i = 0; i < f->size(); ++i) c.filters.push_back(parse_spectrum(f->at(i), SpectrumKind::kTransmittance));
  c.black_level = s.number_or("black_level", 0.0);
  if (auto cc = r.find("candidates")) {
    cc->check_keys({"channel_gain", "crosstalk", "offset", "nonlinearity", "qe_shift", "nir_leak"});
    auto& o = c.candidates;
    o.gain = candidate_on(*cc, "channel_gain");
    o.crosstalk = candidate_on(*cc, "crosstalk");
    o.offset = candidate_on(*cc, "offset");
    o.nonlinearity = candidate_on(*cc, "nonlinearity");
    o.qe_shift = candidate_on(*cc, "qe_shift");
    o.nir_leak = candidate_on(*cc, "nir_leak");
  }
}

}  // namespace

DiagnoseModelFile load_diagnose_model(const std::filesystem::path& file) {
  JsonFile f = JsonFile::load(file);
  JsonNode r = f.root();
  if (!r.is_object()) r.fail("a diagnose model must be a JSON object");
  DiagnoseModelFile m;
  m.file = file.string();
  std::string kind = r.at("kind").string();
  if (kind != "spectra" && kind != "camera") r.at("kind").fail("must be \"spectra\" or \"camera\"");
  m.kind = kind == "camera" ? InputKind::kCamera : InputKind::kSpectra;
  if (auto s = r.find("select")) m.select = parse_select(*s);
  parse_selection(r, m);
  if (m.kind == InputKind::kSpectra)
    parse_spectra(r, m);
  else
    parse_camera(r, m);
  return m;
}

RowFilter parse_where(const std::string& s, const std::string& option, const std::string& separators) {
  auto eq = s.find('=');
  if (eq == std::string::npos || eq == 0) {
    std::string form = separators.find(',') != std::string::npos ? "column=a,b" : "column=value";
    throw InputError("command line", option, "expected " + form + ", got \"" + s + "\"");
  }
  RowFilter f;
  f.column = s.substr(0, eq);
  std::string rest = s.substr(eq + 1);
  size_t a = 0;
  for (;;) {
    size_t b = rest.find_first_of(separators, a);
    f.values.push_back(rest.substr(a, b == std::string::npos ? std::string::npos : b - a));
    if (b == std::string::npos) break;
    a = b + 1;
  }
  return f;
}

nlohmann::json DiagnoseJob::to_json() const {
  nlohmann::json j = {{"input", input}, {"model", model}, {"outdir", outdir}, {"json", json}, {"where", where}, {"groups", groups}};
  j["z"] = z ? nlohmann::json(*z) : nlohmann::json(nullptr);
  j["max_causes"] = max_causes ? nlohmann::json(*max_causes) : nlohmann::json(nullptr);
  j["report_by"] = report_by;
  j["shared_concentrations"] = shared_concentrations;
  j["tissue_per"] = tissue_per;
  j["fit_on"] = fit_on;
  j["predict"] = predict;
  return j;
}

}  // namespace ofl
