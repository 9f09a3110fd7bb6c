#include "renderer/sweep/design/sweep_spec.h"

#include <cmath>
#include <cctype>
#include <set>

#include "renderer/core/errors/error.h"

namespace ofl {
namespace {

// The rig generators (rig_generators.h applies them): their names and the levels each takes are
// part of the sweep file's format (docs/sweep-format.md), so the parser checks them here.
const char* const kGenerators[] = {"led_count",       "ring_radius",        "led_tilt", "rig_distance",
                                   "led_half_angle",  "led_filter_edge",    "camera_filter_edge",
                                   "led_fwhm",        "scene_file",         "camera_file"};

bool is_rig_generator(const std::string& name) {
  for (const char* g : kGenerators)
    if (name == g) return true;
  return false;
}

std::string rig_generator_names() {
  std::string s;
  for (const char* g : kGenerators) s += (s.empty() ? "" : ", ") + std::string(g);
  return s;
}

void check_generator_values(const SweepParameter& p, const JsonNode& n) {
  const std::string& g = p.generator;
  auto field = [&]() { return n.has("values") ? n.at("values") : n.at("range"); };
  if (g == "scene_file" || g == "camera_file") {
    if (p.range) field().fail("file generators take a list of file names, not a range");
    for (size_t i = 0; i < p.values.size(); ++i) {
      JsonNode v = n.at("values").at(i);
      v.existing_file();  // string, and the file exists
    }
    return;
  }
  double lo = -1e300, hi = 1e300;
  if (g == "led_count") lo = 1, hi = 1000;
  else if (g == "ring_radius") lo = 0, hi = 10;
  else if (g == "led_tilt") lo = -89, hi = 89;
  else if (g == "rig_distance") lo = 1e-6, hi = 1e3;
  else if (g == "led_half_angle") lo = 0.5, hi = 89.5;
  else if (g == "led_filter_edge" || g == "camera_filter_edge") lo = 1, hi = 1e5;
  else if (g == "led_fwhm") lo = 1e-3, hi = 1e4;
  for (size_t i = 0; i < p.values.size(); ++i) {
    const auto& v = p.values[i];
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo || v.get<double>() > hi) {
      std::string what = "generator " + g + " takes numbers in [" + nlohmann::json(lo).dump() + ", " +
                         nlohmann::json(hi).dump() + "], got " + v.dump();
      if (n.has("values")) n.at("values").at(i).fail(what);
      field().fail(what);
    }
    if (g == "led_count" && !v.is_number_integer()) {
      if (n.has("values")) n.at("values").at(i).fail("led_count takes integers");
      field().fail("led_count takes integers: add \"integer\": true to the range");
    }
  }
}

// "/a/b" with every token present; the pointer is only checked for syntax here (the documents it
// points into are checked when the design is validated).
std::string pointer_string(const JsonNode& n) {
  std::string s = n.string();
  if (s.empty() || s[0] != '/') n.fail("expected a JSON pointer such as \"/lights/0/ring_radius_m\"");
  try {
    nlohmann::json::json_pointer p(s);
  } catch (const std::exception& e) {
    n.fail(std::string("not a valid JSON pointer: ") + e.what());
  }
  return s;
}

ParamRange parse_range(const JsonNode& n) {
  n.check_keys({"min", "max", "steps", "scale", "integer"});
  ParamRange r;
  r.min = n.at("min").number();
  r.max = n.at("max").number();
  if (!(r.max > r.min)) n.at("max").fail("must be greater than min");
  r.steps = n.integer_or("steps", 2, 2, 100000);
  r.log = n.choice_or("scale", "linear", {"linear", "log"}) == "log";
  if (r.log && !(r.min > 0)) n.at("min").fail("a log range needs min > 0");
  r.integer = n.boolean_or("integer", false);
  return r;
}

std::vector<std::pair<std::string, nlohmann::json>> parse_edits(const JsonNode& n) {
  std::vector<std::pair<std::string, nlohmann::json>> out;
  if (!n.is_object()) n.fail("expected an object from JSON pointer to value");
  for (const auto& k : n.keys()) {
    // Keys are pointers; report a bad one at its own path.
    JsonNode v = n.at(k);
    if (k.empty() || k[0] != '/') v.fail("keys must be JSON pointers such as \"/materials/tongue/coating\"");
    try {
      nlohmann::json::json_pointer p(k);
    } catch (const std::exception& e) {
      v.fail(std::string("key is not a valid JSON pointer: ") + e.what());
    }
    out.emplace_back(k, v.raw());
  }
  return out;
}

SweepParameter parse_parameter(const JsonNode& n) {
  n.check_keys({"name", "scene", "camera", "generator", "light", "filter", "peak_nm", "values", "range", "variants"});
  SweepParameter p;
  p.where = n.path();
  p.name = n.at("name").string();
  if (p.name.empty()) n.at("name").fail("must not be empty");
  for (char c : p.name)
    if (c == ',' || c == '"' || c == '\n' || c == '.') n.at("name").fail("must not contain , \" . or a line break (it is a CSV column)");
  int kinds = n.has("scene") + n.has("camera") + n.has("generator") + n.has("variants");
  if (kinds != 1) n.fail("give exactly one of scene (a JSON pointer), camera (a JSON pointer), generator, variants");
  if (auto s = n.find("scene")) {
    p.kind = ParamKind::kScenePath;
    p.pointer = pointer_string(*s);
  } else if (auto c = n.find("camera")) {
    p.kind = ParamKind::kCameraPath;
    p.pointer = pointer_string(*c);
  } else if (auto g = n.find("generator")) {
    p.kind = ParamKind::kGenerator;
    p.generator = g->string();
    if (!is_rig_generator(p.generator)) g->fail("unknown generator \"" + p.generator + "\" (have: " + rig_generator_names() + ")");
  } else {
    p.kind = ParamKind::kVariants;
  }
  p.light = n.integer_or("light", 0, 0, 10000);
  p.filter = n.integer_or("filter", -1, -1, 10000);
  if (auto pk = n.find("peak_nm")) p.peak_nm = pk->positive();
  if (p.kind != ParamKind::kGenerator)
    for (const char* k : {"light", "filter", "peak_nm"})
      if (n.has(k)) n.at(k).fail("only generators take this field");

  if (p.kind == ParamKind::kVariants) {
    if (n.has("values") || n.has("range")) n.fail("variants give their own levels: leave out values and range");
    JsonNode vs = n.at("variants");
    if (vs.size() < 1) vs.fail("needs at least one variant");
    std::set<std::string> labels;
    for (size_t i = 0; i < vs.size(); ++i) {
      JsonNode v = vs.at(i);
      v.check_keys({"label", "scene", "camera"});
      Variant var;
      var.label = v.at("label").string();
      if (var.label.empty()) v.at("label").fail("must not be empty");
      if (!labels.insert(var.label).second) v.at("label").fail("duplicate label \"" + var.label + "\"");
      if (auto s = v.find("scene")) var.scene_edits = parse_edits(*s);
      if (auto c = v.find("camera")) var.camera_edits = parse_edits(*c);
      p.values.push_back(var.label);
      p.variants.push_back(std::move(var));
    }
    return p;
  }
  if (n.has("values") == n.has("range")) n.fail("give exactly one of values (a list) or range ({min, max, steps})");
  if (auto v = n.find("values")) {
    if (!v->is_array() || v->size() == 0) v->fail("expected a non-empty list of values");
    for (size_t i = 0; i < v->size(); ++i) p.values.push_back(v->at(i).raw());
  } else {
    JsonNode rn = n.at("range");
    ParamRange r = parse_range(rn);
    p.range = r;
    for (int i = 0; i < r.steps; ++i) {
      double t = double(i) / (r.steps - 1);
      double x = r.log ? std::exp(std::log(r.min) + t * (std::log(r.max) - std::log(r.min))) : r.min + t * (r.max - r.min);
      if (r.integer) p.values.push_back(static_cast<long long>(std::llround(x)));
      else p.values.push_back(x);
    }
    if (r.integer) {  // rounding may merge levels
      std::vector<nlohmann::json> unique;
      for (auto& v : p.values)
        if (unique.empty() || unique.back() != v) unique.push_back(v);
      p.values = unique;
    }
  }
  if (p.kind == ParamKind::kGenerator) check_generator_values(p, n);
  return p;
}

TextureCondition parse_condition(const JsonNode& n, const char* file_key) {
  TextureCondition c;
  c.file = n.at(file_key).existing_file();
  if (!n.has("above") && !n.has("below")) n.fail("a texture needs a threshold: above and/or below");
  if (auto a = n.find("above")) c.above = a->number();
  if (auto b = n.find("below")) c.below = b->number();
  if (!(c.below > c.above)) n.fail("below must be greater than above");
  return c;
}

// {"name", "material", "texture", "above", "below"} or {"name", "material", "textures": [{"file",
// "above", "below"}, ...]}.
RoiSpec parse_roi_spec(const JsonNode& n) {
  n.check_keys({"name", "material", "texture", "above", "below", "textures"});
  RoiSpec r;
  r.name = n.at("name").string();
  if (r.name.empty()) n.at("name").fail("must not be empty");
  for (char c : r.name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'))
      n.at("name").fail("use letters, digits, _ and - only (it prefixes CSV columns)");
  r.material = n.at("material").string();
  if (n.has("texture")) {
    if (n.has("textures")) n.fail("give texture (one condition) or textures (a list), not both");
    r.textures.push_back(parse_condition(n, "texture"));
  } else if (n.has("above") || n.has("below")) {
    n.fail("above/below threshold a texture: give texture");
  }
  if (auto ts = n.find("textures")) {
    for (size_t i = 0; i < ts->size(); ++i) {
      JsonNode t = ts->at(i);
      t.check_keys({"file", "above", "below"});
      r.textures.push_back(parse_condition(t, "file"));
    }
  }
  return r;
}

}  // namespace

bool SweepParameter::numeric() const {
  for (auto& v : values)
    if (!v.is_number()) return false;
  return !values.empty();
}

const RoiSpec* SweepSpec::roi(const std::string& n) const {
  for (auto& r : rois)
    if (r.name == n) return &r;
  return nullptr;
}

const std::vector<std::string>& default_report_metrics() {
  static const std::vector<std::string> m = {"irr_cv",        "irr_p5_p95",     "int_cv",        "r_std",
                                             "g_std",         "ellipse_area",   "r_std_nf",      "corr_irr_r",
                                             "share_fluorescence", "share_leak", "snr_G",       "r_mean"};
  return m;
}

namespace {

void parse_render_settings(const JsonNode& r, RenderSettings& out) {
  r.check_keys({"width", "height", "spp", "max_depth", "seed", "noise_target", "output_bands", "replicates", "cache"});
  out.replicates = r.integer_or("replicates", 1, 1, 2);
  out.cache = r.boolean_or("cache", true);
  if (auto v = r.find("width")) out.width = v->integer(2, 16384);
  if (auto v = r.find("height")) out.height = v->integer(2, 16384);
  if (auto v = r.find("spp")) out.spp = v->integer(1, 1 << 24);
  if (auto v = r.find("max_depth")) out.max_depth = v->integer(0, 1000);
  if (auto v = r.find("seed")) out.seed = static_cast<uint64_t>(v->integer(0));
  if (auto v = r.find("noise_target")) out.noise_target = v->number(0.0, 10.0);
  if (auto v = r.find("output_bands")) {
    v->check_keys({"min_nm", "max_nm", "step_nm"});
    double lo = v->at("min_nm").positive(), hi = v->at("max_nm").positive(), st = v->at("step_nm").positive();
    if (!(hi > lo)) v->at("max_nm").fail("must be greater than min_nm");
    out.output_bands = nlohmann::json{{"min_nm", lo}, {"max_nm", hi}, {"step_nm", st}};
  }
}

void parse_design(const JsonNode& d, DesignSpec& out) {
  d.check_keys({"type", "points", "seed"});
  std::string t = d.choice_or("type", "grid", {"grid", "latin_hypercube"});
  if (t == "latin_hypercube") {
    out.type = DesignSpec::Type::kLatinHypercube;
    out.points = static_cast<int>(d.at("points").integer(1, kMaxSweepPoints));
    out.seed = static_cast<uint64_t>(d.integer_or("seed", 1, 0));
  } else if (d.has("points") || d.has("seed")) {
    d.fail("points and seed belong to a latin_hypercube design; a grid takes every combination");
  }
}

// The parameters, with unique names, and a grid that fits in a sweep.
void parse_parameters(const JsonNode& ps, SweepSpec& s) {
  std::set<std::string> names;
  for (size_t i = 0; i < ps.size(); ++i) {
    SweepParameter p = parse_parameter(ps.at(i));
    if (!names.insert(p.name).second) ps.at(i).at("name").fail("duplicate parameter name \"" + p.name + "\"");
    s.parameters.push_back(std::move(p));
  }
  if (s.parameters.empty()) ps.fail("needs at least one parameter");
  if (s.design.type == DesignSpec::Type::kGrid) {
    double total = 1;
    for (auto& p : s.parameters) total *= p.levels();
    if (total > kMaxSweepPoints)
      ps.fail("the full grid has " + std::to_string(static_cast<long long>(total)) + " points, more than the " +
              std::to_string(kMaxSweepPoints) + " a sweep can run; use fewer levels or a latin_hypercube design");
  }
}

void parse_rois(const JsonNode* rs, SweepSpec& s) {
  if (!rs) {
    s.rois.push_back(RoiSpec{"tongue", "tongue", {}});
    return;
  }
  for (size_t i = 0; i < rs->size(); ++i) {
    RoiSpec r = parse_roi_spec(rs->at(i));
    if (s.roi(r.name)) rs->at(i).at("name").fail("duplicate ROI name \"" + r.name + "\"");
    s.rois.push_back(std::move(r));
  }
}

void parse_lesion_contrast(const JsonNode& lc, SweepSpec& s) {
  lc.check_keys({"lesion", "healthy"});
  s.metrics.lesion_roi = lc.at("lesion").string();
  s.metrics.healthy_roi = lc.at("healthy").string();
  if (!s.roi(s.metrics.lesion_roi)) lc.at("lesion").fail("no ROI named \"" + s.metrics.lesion_roi + "\"");
  if (!s.roi(s.metrics.healthy_roi)) lc.at("healthy").fail("no ROI named \"" + s.metrics.healthy_roi + "\"");
  if (s.metrics.lesion_roi == s.metrics.healthy_roi) lc.at("healthy").fail("must differ from lesion");
}

void parse_report(const JsonNode& r, SweepSpec& s) {
  r.check_keys({"metrics", "thumbnail_width", "scatter", "scatter_rois"});
  s.report.scatter_noise_free = r.choice_or("scatter", "raw", {"raw", "noise_free"}) == "noise_free";
  if (auto sr = r.find("scatter_rois"))
    for (size_t i = 0; i < sr->size(); ++i) {
      std::string n = sr->at(i).string();
      if (!s.roi(n)) sr->at(i).fail("no ROI named \"" + n + "\"");
      s.report.scatter_rois.push_back(n);
    }
  if (auto ms = r.find("metrics")) {
    s.report.metrics.clear();
    for (size_t i = 0; i < ms->size(); ++i) s.report.metrics.push_back(ms->at(i).string());
  }
  s.report.thumbnail_width = r.integer_or("thumbnail_width", s.report.thumbnail_width, 16, 1024);
}

}  // namespace

SweepSpec parse_sweep_spec(const JsonFile& f) {
  JsonNode root = f.root();
  root.check_keys({"format", "version", "name", "description", "scene", "camera", "render", "camera_run", "design",
                   "parameters", "rois", "lesion_contrast", "metrics", "report"});
  if (root.string_or("format", "oralfluor-sweep") != "oralfluor-sweep")
    root.at("format").fail("expected \"oralfluor-sweep\"");
  if (auto v = root.find("version")) {
    int ver = v->integer();
    if (ver != 1) v->fail("unsupported sweep format version " + std::to_string(ver) + " (this build reads 1)");
  }
  SweepSpec s;
  s.file = f.name();
  s.name = root.string_or("name", std::filesystem::path(f.name()).stem().string());
  s.description = root.string_or("description", "");
  s.scene = root.at("scene").existing_file();
  s.camera = root.at("camera").existing_file();
  if (auto r = root.find("render")) parse_render_settings(*r, s.render);
  if (auto c = root.find("camera_run")) {
    c->check_keys({"noise", "seed"});
    if (auto v = c->find("noise")) s.camera_run.noise = v->boolean();
    if (auto v = c->find("seed")) s.camera_run.seed = static_cast<uint64_t>(v->integer(0));
  }
  if (auto d = root.find("design")) parse_design(*d, s.design);
  parse_parameters(root.at("parameters"), s);
  const auto rs = root.find("rois");
  parse_rois(rs ? &*rs : nullptr, s);
  if (auto lc = root.find("lesion_contrast")) parse_lesion_contrast(*lc, s);
  if (auto m = root.find("metrics")) {
    m->check_keys({"led_band_threshold", "scatter_cells"});
    s.metrics.led_band_threshold = m->number_or("led_band_threshold", s.metrics.led_band_threshold, 1e-9, 1.0);
    s.metrics.scatter_cells = m->integer_or("scatter_cells", s.metrics.scatter_cells, 0, 100000);
  }
  s.report.metrics = default_report_metrics();
  if (auto r = root.find("report")) parse_report(*r, s);
  return s;
}

SweepSpec load_sweep_spec(const std::filesystem::path& file) { return parse_sweep_spec(JsonFile::load(file)); }

void describe_target(const SweepParameter& p, nlohmann::json& j) {
  switch (p.kind) {
    case ParamKind::kScenePath: j["scene"] = p.pointer; break;
    case ParamKind::kCameraPath: j["camera"] = p.pointer; break;
    case ParamKind::kGenerator:
      j["generator"] = p.generator;
      j["light"] = p.light;
      j["filter"] = p.filter;
      j["peak_nm"] = p.peak_nm;
      break;
    case ParamKind::kVariants: break;
  }
}

nlohmann::json SweepSpec::to_json() const {
  auto opt = [](const auto& o) -> nlohmann::json { return o ? nlohmann::json(*o) : nlohmann::json(nullptr); };
  nlohmann::json params = nlohmann::json::array();
  for (auto& p : parameters) {
    nlohmann::json j = {{"name", p.name}, {"values", p.values}};
    describe_target(p, j);
    switch (p.kind) {
      case ParamKind::kScenePath:
      case ParamKind::kCameraPath:
      case ParamKind::kGenerator: break;
      case ParamKind::kVariants: {
        nlohmann::json vs = nlohmann::json::array();
        for (auto& v : p.variants) {
          nlohmann::json e = {{"label", v.label}, {"scene", nlohmann::json::object()}, {"camera", nlohmann::json::object()}};
          for (auto& [k, x] : v.scene_edits) e["scene"][k] = x;
          for (auto& [k, x] : v.camera_edits) e["camera"][k] = x;
          vs.push_back(e);
        }
        j["variants"] = vs;
        break;
      }
    }
    if (p.range) j["range"] = {{"min", p.range->min}, {"max", p.range->max}, {"steps", p.range->steps},
                               {"log", p.range->log}, {"integer", p.range->integer}};
    params.push_back(j);
  }
  nlohmann::json rois_j = nlohmann::json::array();
  for (auto& r : rois) {
    nlohmann::json j = {{"name", r.name}, {"material", r.material}, {"textures", nlohmann::json::array()}};
    for (auto& t : r.textures) {
      nlohmann::json c = {{"file", t.file.string()}};
      if (std::isfinite(t.above)) c["above"] = t.above;
      if (std::isfinite(t.below)) c["below"] = t.below;
      j["textures"].push_back(c);
    }
    rois_j.push_back(j);
  }
  return {{"format", "oralfluor-sweep"},
          {"version", 1},
          {"file", file},
          {"name", name},
          {"scene", scene.string()},
          {"camera", camera.string()},
          {"render", {{"width", opt(render.width)}, {"height", opt(render.height)}, {"spp", opt(render.spp)},
                      {"max_depth", opt(render.max_depth)}, {"seed", opt(render.seed)},
                      {"noise_target", opt(render.noise_target)}, {"output_bands", opt(render.output_bands)},
                      {"replicates", render.replicates}, {"cache", render.cache}}},
          {"camera_run", {{"noise", opt(camera_run.noise)}, {"seed", opt(camera_run.seed)}}},
          {"design", {{"type", design.type == DesignSpec::Type::kGrid ? "grid" : "latin_hypercube"},
                      {"points", design.points}, {"seed", design.seed}}},
          {"parameters", params},
          {"rois", rois_j},
          {"metrics", {{"led_band_threshold", metrics.led_band_threshold}, {"lesion_roi", metrics.lesion_roi},
                       {"healthy_roi", metrics.healthy_roi}}}};
}

}  // namespace ofl
