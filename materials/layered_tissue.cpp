// {"type": "layered_tissue", ...}: oral mucosa as a stack of scattering layers (materials/description/layered.h).
//   "preset": "dorsal_tongue"        start from assets/tissues/layered/<preset>.json; the fields below
//                                    then override it ("layers" as an object keyed by layer name
//                                    merges into the preset's layers, "fluorophores" inside a layer
//                                    as an object keyed by fluorophore name merges likewise)
//   "coating": {"ior": 1.33, "roughness": 0.25, "thickness_mm": 0} | false
//                                    wet film on top: a clear layer whose upper face is a rough
//                                    (GGX) dielectric interface; false or absent = smooth bare top
//   "ambient_ior": 1.0               medium above the tissue
//   "layers": [<layer>, ...]         top to bottom
//   "transport": "table" | "spatial" | "walk"
//                                    table (default): the stack's response tabulated once at scene load
//                                    (renderer/render/stack/stack_response.h), light leaves where it entered;
//                                    spatial: the same table for the directional part and lateral
//                                    profiles for where light comes back out (renderer/render/spatial/);
//                                    walk: the position-free random walk at every shading point (the
//                                    reference)
//   "table_photons": 2000            walks per incidence cosine and wavelength group filling the table
//   "profile_photons": 20000         spatial: walks per incidence cosine and wavelength group filling the
//                                    lateral profiles
//   "table_similarity_after": 60     collisions after which the table's walks scatter isotropically with
//                                    mus (1 - g) (the similarity relation); 0 = the exact phase throughout
//   "bottom": "semi_infinite" | {"type": "open", "ior": 1.0}
//           | {"type": "base", "reflectance": <spectrum>, "fluorophores": [<surface fluorophore>]}
// A layer:
//   {"name": "epithelium", "thickness_mm": 0.3 | "infinite", "ior": 1.37,
//    "scattering": {"g": 0.9, "mus_prime_per_mm": {"a": 2.0, "b": 1.2, "f_rayleigh": 0}}
//                | {"g": 0.9, "mus_prime_per_mm": <spectrum>} | {"g": 0.9, "mus_per_mm": <spectrum>},
//    "absorption": {"baseline_per_mm": 0.01 | <spectrum> | "jacques_skin_baseline",
//                   "blood": {"volume_fraction": 0.02, "saturation": 0.75, "hemoglobin_g_per_L": 150,
//                             "vessel_radius_um": 0},
//                   "melanin": {"volume_fraction": 0.0}, "mua_per_mm": <spectrum>},
//    "fluorophores": [{"name": "NADH", "mua_per_mm": 0.02, "quantum_yield": 0.05, "texture": ...}]}
// The power law is mus'(lambda) = a [f_R (lambda/500)^-4 + (1 - f_R) (lambda/500)^-b] in 1/mm
// (Jacques, Phys Med Biol 58 R37, 2013) and mus = mus' / (1 - g).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "materials/material_parser.h"
#include "renderer/core/files/asset_path.h"
#include "renderer/core/errors/error.h"
#include "renderer/spectral/chromophores/hemoglobin.h"
#include "renderer/spectral/spectrum_json.h"

namespace ofl {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A coefficient table must cover the transport grid: a table silently extended as zero would drop
// scattering or absorption where it is not measured.
std::vector<double> parse_coefficient(const JsonNode& n, const WavelengthGrid& grid) {
  Spectrum s = parse_spectrum(n, SpectrumKind::kEmission);
  bool table = n.is_string() || (n.is_object() && (n.at("type").string() == "csv" || n.at("type").string() == "points"));
  if (table && !s.kinks.empty()) {
    double lo = s.kinks.front(), hi = s.kinks.back();
    bool clamp = n.is_object() && n.string_or("outside", "zero") == "clamp";
    if (!clamp && (grid.bin_lo(0) < lo - 1e-9 || grid.bin_hi(grid.size() - 1) > hi + 1e-9)) {
      std::ostringstream m;
      m << "the table covers " << lo << "-" << hi << " nm but the transport grid spans " << grid.bin_lo(0) << "-"
        << grid.bin_hi(grid.size() - 1) << " nm; extend the table, narrow integrator.wavelengths, or give "
        << "\"outside\": \"clamp\" to hold its end values";
      n.fail(m.str());
    }
  }
  std::vector<double> v = tabulate(s, grid);
  check_tabulated(n, v, grid, SpectrumKind::kEmission);
  return v;
}

std::vector<double> power_law_mus_prime(const JsonNode& n, const WavelengthGrid& grid) {
  n.check_keys({"a", "b", "f_rayleigh"});
  double a = n.at("a").number(0.0, 1e5);
  double b = n.at("b").number(0.0, 10.0);
  double fr = n.number_or("f_rayleigh", 0.0, 0.0, 1.0);
  Spectrum s;
  s.eval = [=](double nm) {
    double x = nm / 500.0;
    return a * (fr * std::pow(x, -4.0) + (1.0 - fr) * std::pow(x, -b));
  };
  s.description = "scattering power law";
  return tabulate(s, grid);
}

void parse_scattering(const JsonNode& n, TissueLayer& layer, const WavelengthGrid& grid) {
  n.check_keys({"g", "mus_prime_per_mm", "mus_per_mm"});
  layer.g = n.number_or("g", 0.9, -0.99, 0.99);
  if (n.has("mus_prime_per_mm") == n.has("mus_per_mm")) n.fail("give exactly one of mus_prime_per_mm or mus_per_mm");
  if (auto p = n.find("mus_prime_per_mm")) {
    layer.mus = (p->is_object() && !p->has("type")) ? power_law_mus_prime(*p, grid) : parse_coefficient(*p, grid);
    for (double& v : layer.mus) v /= (1.0 - layer.g);
  } else {
    layer.mus = parse_coefficient(n.at("mus_per_mm"), grid);
  }
}

void add_to(std::vector<double>& a, const std::vector<double>& b) {
  for (size_t i = 0; i < a.size(); ++i) a[i] += b[i];
}

void parse_absorption(const JsonNode& n, TissueLayer& layer, const WavelengthGrid& grid) {
  n.check_keys({"baseline_per_mm", "blood", "melanin", "mua_per_mm"});
  if (auto b = n.find("baseline_per_mm")) {
    if (b->is_string() && b->string() == "jacques_skin_baseline") {
      // Bloodless dermis (Jacques 1998, "Skin optics", OMLC News): 0.244 + 85.3 exp(-(l - 154) / 66.2) 1/cm.
      Spectrum s;
      s.eval = [](double nm) { return 0.1 * (0.244 + 85.3 * std::exp(-(nm - 154.0) / 66.2)); };
      s.description = "Jacques skin baseline";
      add_to(layer.mua, tabulate(s, grid));
    } else {
      add_to(layer.mua, parse_coefficient(*b, grid));
    }
  }
  if (auto b = n.find("blood")) {
    b->check_keys({"volume_fraction", "saturation", "hemoglobin_g_per_L", "vessel_radius_um"});
    double f = b->at("volume_fraction").number(0.0, 1.0);
    double s = b->number_or("saturation", 0.75, 0.0, 1.0);
    double hb = b->number_or("hemoglobin_g_per_L", 150.0, 0.0, 400.0);
    double r = b->number_or("vessel_radius_um", 0.0, 0.0, 1000.0);
    add_to(layer.mua, tabulate(tissue_blood_mua_spectrum(f, s, hb, r), grid));
  }
  if (auto m = n.find("melanin")) {
    // Melanosome interior: 519 (lambda / 500)^-3.5 1/cm (Jacques 2013, Phys Med Biol 58 R37).
    m->check_keys({"volume_fraction"});
    double f = m->at("volume_fraction").number(0.0, 1.0);
    Spectrum s;
    s.eval = [f](double nm) { return f * 51.9 * std::pow(nm / 500.0, -3.5); };
    s.description = "melanin";
    add_to(layer.mua, tabulate(s, grid));
  }
  if (auto m = n.find("mua_per_mm")) add_to(layer.mua, parse_coefficient(*m, grid));
}

std::vector<LayerFluorophore> parse_layer_fluorophores(const JsonNode& list, MaterialContext& ctx) {
  if (list.size() > size_t(kMaxLayerFluorophores))
    list.fail("has " + std::to_string(list.size()) + " fluorophores; a layer may have at most " + std::to_string(kMaxLayerFluorophores));
  std::vector<LayerFluorophore> out;
  for (size_t i = 0; i < list.size(); ++i) {
    JsonNode f = list.at(i);
    f.check_keys({"name", "eem", "fluorophore", "normalise", "mua_per_mm", "quantum_yield", "texture"});
    LayerFluorophore lf;
    lf.eem = load_fluorophore_eem(f, ctx, &lf.name);
    lf.mua_peak_per_mm = f.at("mua_per_mm").number(0.0, 1e4);
    lf.quantum_yield = f.at("quantum_yield").number(0.0, 1.0);
    if (auto t = f.find("texture")) parse_fluorophore_texture(*t, ctx, &lf.texture, &lf.texture_offset, &lf.texture_scale);
    auto a = (*ctx.eems)[lf.eem].photon_albedo();
    if (*std::max_element(a.begin(), a.end()) <= 0) f.fail("the EEM of \"" + lf.name + "\" absorbs nowhere on the transport grid");
    out.push_back(lf);
  }
  return out;
}

TissueLayer parse_layer(const JsonNode& n, bool last, MaterialContext& ctx) {
  n.check_keys({"name", "thickness_mm", "ior", "scattering", "absorption", "fluorophores"});
  const WavelengthGrid& grid = ctx.grid;
  TissueLayer layer;
  layer.name = n.string_or("name", "layer" + n.path().substr(n.path().rfind('/') + 1));
  if (auto t = n.find("thickness_mm")) {
    if (t->is_string()) {
      if (t->string() != "infinite") t->fail("expected a thickness in mm or \"infinite\"");
      if (!last) t->fail("only the last layer may be semi-infinite");
      layer.thickness_mm = kInf;
    } else {
      layer.thickness_mm = t->number(0.0, 1e4);
    }
  } else {
    if (!last) n.fail("needs thickness_mm (only the last layer may be semi-infinite)");
    layer.thickness_mm = kInf;
  }
  layer.ior = n.number_or("ior", 1.37, 1.0, 3.0);
  layer.mua.assign(grid.size(), 0.0);
  layer.mus.assign(grid.size(), 0.0);
  if (auto s = n.find("scattering")) parse_scattering(*s, layer, grid);
  if (auto a = n.find("absorption")) parse_absorption(*a, layer, grid);
  if (auto f = n.find("fluorophores")) layer.fluorophores = parse_layer_fluorophores(*f, ctx);
  return layer;
}

// Merges `patch` into `target` (RFC 7386 style: objects merge, everything else replaces), except
// that a name-keyed object given where the target holds a list of named entries merges into those
// entries by name. `where` is the user's node for `patch`. A new name adds an entry (a fluorophore
// the preset's layer lacks), except among the preset's "layers": a name the preset does not have
// there is a misspelling, not a new bottom layer, and is refused naming the layer and the
// preset's own layers.
void merge_named(nlohmann::json& target, const nlohmann::json& patch, const JsonNode& where, const std::string& preset,
                 const std::string& key = "") {
  if (target.is_array() && patch.is_object()) {
    for (auto it = patch.begin(); it != patch.end(); ++it) {
      nlohmann::json* hit = nullptr;
      for (auto& e : target)
        if (e.is_object() && e.value("name", "") == it.key()) hit = &e;
      if (hit) {
        merge_named(*hit, it.value(), where.at(it.key()), preset);
        continue;
      }
      if (key == "layers") {
        std::string names;
        for (auto& e : target) names += (names.empty() ? "\"" : ", \"") + (e.is_object() ? e.value("name", "?") : "?") + "\"";
        where.at(it.key()).fail("preset \"" + preset + "\" has no layer \"" + it.key() + "\" (its layers: " + names +
                                "); an override can only change the preset's layers (give \"layers\" as a list for a stack of your own)");
      }
      nlohmann::json e = it.value();
      if (!e.is_object()) where.at(it.key()).fail("\"" + it.key() + "\" is not in the preset; a new entry needs an object");
      e["name"] = it.key();
      target.push_back(e);
    }
    return;
  }
  if (!target.is_object() || !patch.is_object()) {
    target = patch;
    return;
  }
  for (auto it = patch.begin(); it != patch.end(); ++it) {
    if (it.value().is_null()) target.erase(it.key());
    else if (target.contains(it.key())) merge_named(target[it.key()], it.value(), where.at(it.key()), preset, it.key());
    else target[it.key()] = it.value();
  }
}

// Rewrites relative file names inside a document (strings ending in a data-file extension) so a
// merged copy can be parsed from anywhere.
void absolutise_files(nlohmann::json& j, const std::filesystem::path& dir) {
  if (j.is_string()) {
    std::filesystem::path p = j.get<std::string>();
    static const char* exts[] = {".csv", ".mat", ".json", ".png", ".exr", ".tif", ".tiff", ".jpg", ".jpeg", ".ies"};
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (p.is_relative() && std::find_if(std::begin(exts), std::end(exts), [&](const char* e) { return ext == e; }) != std::end(exts))
      j = std::filesystem::absolute(dir / p).string();
  } else if (j.is_object() || j.is_array()) {
    for (auto& e : j) absolutise_files(e, dir);
  }
}

std::filesystem::path preset_file(const JsonNode& p) {
  std::string name = p.string();
  auto dir = asset_root() / "tissues" / "layered";
  auto file = dir / (name + ".json");
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) {
    std::vector<std::string> have;
    for (auto& e : std::filesystem::directory_iterator(dir, ec))
      if (e.path().extension() == ".json") have.push_back(e.path().stem().string());
    std::sort(have.begin(), have.end());
    std::string list;
    for (auto& h : have) list += (list.empty() ? "" : ", ") + h;
    p.fail("no layered tissue preset \"" + name + "\" (have: " + list + ")");
  }
  return file;
}

// The user's document with the preset merged under it (user fields win).
nlohmann::json merged_document(const JsonNode& n) {
  if (!n.has("preset")) return n.raw();
  auto file = preset_file(n.at("preset"));
  JsonFile pf = JsonFile::load(file);
  nlohmann::json mat = pf.root().at("material").raw();
  if (mat.value("type", "") != "layered_tissue") pf.root().at("material").at("type").fail("a layered preset must be of type layered_tissue");
  absolutise_files(mat, file.parent_path());
  nlohmann::json user = n.raw();
  user.erase("preset");
  // The user's own relative file names are relative to the user's file.
  absolutise_files(user, std::filesystem::path(n.file()).parent_path());
  merge_named(mat, user, n, n.at("preset").string());
  return mat;
}

void parse_stack(const JsonNode& m, Material& out, MaterialContext& ctx) {
  m.check_keys({"type", "coating", "ambient_ior", "layers", "bottom", "transport", "table_photons",
                "table_similarity_after", "profile_photons"});
  LayerStack& st = out.stack;
  st.enabled = true;
  if (auto t = m.find("transport")) {
    std::string v = t->string();
    if (v == "table") st.transport = StackTransport::kTable;
    else if (v == "walk") st.transport = StackTransport::kWalk;
    else if (v == "spatial") st.transport = StackTransport::kSpatial;
    else if (v == "volume") st.transport = StackTransport::kVolume;
    else t->fail("expected \"table\", \"spatial\", \"walk\" or \"volume\"");
  }
  if (auto t = m.find("profile_photons")) {
    if (st.transport != StackTransport::kSpatial) t->fail("only a \"spatial\" transport has lateral profiles to fill");
    double v = t->number(100.0, 1e7);
    if (v != std::floor(v)) t->fail("expected a whole number of walks");
    st.profile_photons = int(v);
  }
  if (auto t = m.find("table_photons")) st.table_photons = int(t->number(100.0, 1e7));
  if (auto t = m.find("table_similarity_after")) {
    double v = t->number(0.0, 1e6);
    if (v != std::floor(v)) t->fail("expected a whole number of collisions (0 = never)");
    st.table_similarity_after = int(v);
  }
  st.ambient_ior = m.number_or("ambient_ior", 1.0, 1.0, 3.0);
  if (auto c = m.find("coating"); c && !(c->raw().is_boolean() && !c->boolean())) {
    if (c->raw().is_boolean()) c->fail("give the coating as an object {\"ior\", \"roughness\", \"thickness_mm\"} or false");
    c->check_keys({"ior", "roughness", "thickness_mm"});
    TissueLayer film;
    film.name = "coating";
    film.ior = c->number_or("ior", 1.33, 1.0, 3.0);
    film.thickness_mm = c->number_or("thickness_mm", 0.0, 0.0, 10.0);
    film.g = 0;
    film.mua.assign(ctx.grid.size(), 0.0);
    film.mus.assign(ctx.grid.size(), 0.0);
    st.top_roughness = c->number_or("roughness", 0.25, 0.0, 1.0);
    st.layers.push_back(film);
  }
  JsonNode layers = m.at("layers");
  if (!layers.is_array()) layers.fail("expected a list of layers (an object keyed by layer name only overrides a preset)");
  if (layers.size() == 0) layers.fail("needs at least one layer");
  if (layers.size() + st.layers.size() > size_t(kMaxStackLayers))
    layers.fail("at most " + std::to_string(kMaxStackLayers) + " layers (the coating counts as one)");
  for (size_t i = 0; i < layers.size(); ++i) st.layers.push_back(parse_layer(layers.at(i), i + 1 == layers.size(), ctx));

  out.reflectance.assign(ctx.grid.size(), 0.0);
  bool last_infinite = st.layers.back().semi_infinite();
  st.bottom = StackBottom::kSemiInfinite;
  if (auto b = m.find("bottom")) {
    if (b->is_string()) {
      if (b->string() != "semi_infinite") b->fail("expected \"semi_infinite\" or an object with type open or base");
    } else {
      std::string type = b->at("type").string();
      if (type == "open") {
        b->check_keys({"type", "ior"});
        st.bottom = StackBottom::kOpen;
        st.below_ior = b->number_or("ior", 1.0, 1.0, 3.0);
      } else if (type == "base") {
        b->check_keys({"type", "reflectance", "fluorophores"});
        st.bottom = StackBottom::kBase;
        if (auto r = b->find("reflectance")) out.reflectance = parse_reflectance(*r, ctx.grid);
        if (auto f = b->find("fluorophores")) out.fluorophores = parse_fluorophore_layers(*f, ctx);
      } else {
        b->at("type").fail("unknown bottom \"" + type + "\" (expected open or base)");
      }
    }
    if (st.bottom != StackBottom::kSemiInfinite && last_infinite)
      b->fail("the last layer is semi-infinite, so nothing lies below it; give it a thickness_mm");
  }
  if (st.bottom == StackBottom::kSemiInfinite && !last_infinite)
    layers.at(layers.size() - 1).fail("the last layer has a finite thickness: make it \"infinite\" or give \"bottom\" "
                                      "({\"type\": \"open\"} for a slab with clear space below, or a base)");
}

}  // namespace

Material parse_layered_tissue(const JsonNode& n, MaterialContext& ctx) {
  Material out;
  if (!n.has("preset")) {
    parse_stack(n, out, ctx);
    return out;
  }
  // Parse the merged document; errors name the preset and the user's entry.
  auto file = preset_file(n.at("preset"));
  JsonFile merged = JsonFile::from(merged_document(n), file.string() + " (preset as modified by " + n.file() + " " + n.path() + ")");
  parse_stack(merged.root(), out, ctx);
  return out;
}

}  // namespace ofl
