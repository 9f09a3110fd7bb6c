// {"type": "tissue", "preset": "tongue" | "lip" | "mucosa" | "teeth", ...overrides} and the alias
// {"type": "teeth", ...}: oral tissue built from shipped measurements. A preset
// (assets/tissues/<preset>.json) is a coated fluorescent material with measured reflectance and
// calibrated fluorophore concentrations (each preset says how it was calibrated). Overrides:
//   "reflectance": <spectrum>                 replaces the base reflectance
//   "concentrations": {"FAD": 4e-4, ...}      sets (or adds) library fluorophores
//   "fluorescence_scale": 0.5                 multiplies every concentration
//   "textures": {"protoporphyrin": "patch.png" | {"file": ..., "offset": 1, "scale": -0.5}}
//   "extra_fluorophores": [<fluorophore layer>, ...]   appended as written (e.g. a second
//                                             protoporphyrin layer mapped to a lesion)
//   "coating": {"ior": 1.33, "roughness": 0.25} | false
#include <filesystem>

#include "materials/material_parser.h"
#include "renderer/core/asset_path.h"
#include "renderer/core/error.h"

namespace ofl {

Material parse_tissue(const JsonNode& n, MaterialContext& ctx, const std::string& forced_preset) {
  n.check_keys({"type", "preset", "reflectance", "concentrations", "fluorescence_scale", "textures", "extra_fluorophores", "coating"});
  std::string preset = forced_preset.empty() ? n.at("preset").string() : n.string_or("preset", forced_preset);
  auto file = asset_root() / "tissues" / (preset + ".json");
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) {
    std::string have;
    for (auto& e : std::filesystem::directory_iterator(asset_root() / "tissues", ec))
      if (e.path().extension() == ".json") have += (have.empty() ? "" : ", ") + e.path().stem().string();
    (forced_preset.empty() ? n.at("preset") : n).fail("no tissue preset \"" + preset + "\" (have: " + have + ")");
  }
  JsonFile pf = JsonFile::load(file);
  nlohmann::json mat = pf.root().at("material").raw();  // a copy we edit
  nlohmann::json& base = mat["base"];
  auto abs = [](const std::filesystem::path& p) { return std::filesystem::absolute(p).string(); };
  // Paths inside the preset are relative to the preset; rewrite them so the edited copy can live anywhere.
  if (base["reflectance"].is_object() && base["reflectance"].contains("file"))
    base["reflectance"]["file"] = abs(file.parent_path() / base["reflectance"]["file"].get<std::string>());

  // User overrides, validated against the user's own JSON pointer before they are merged.
  if (auto r = n.find("reflectance")) {
    nlohmann::json v = r->raw();
    if (v.is_string()) v = abs(r->existing_file());
    else if (v.is_object() && v.contains("file")) v["file"] = abs(r->at("file").existing_file());
    base["reflectance"] = v;
  }
  auto find_layer = [&](const std::string& name) -> nlohmann::json* {
    for (auto& l : base["fluorophores"])
      if (l.value("name", "") == name) return &l;
    return nullptr;
  };
  if (auto cs = n.find("concentrations")) {
    for (const auto& k : cs->keys()) {
      double c = cs->at(k).number(0.0, 1.0);
      if (auto* l = find_layer(k)) (*l)["concentration"] = c;
      else base["fluorophores"].push_back({{"name", k}, {"concentration", c}});
    }
  }
  if (auto s = n.find("fluorescence_scale")) {
    double f = s->number(0.0, 1e4);
    for (auto& l : base["fluorophores"]) l["concentration"] = l["concentration"].get<double>() * f;
  }
  if (auto ts = n.find("textures")) {
    for (const auto& k : ts->keys()) {
      JsonNode t = ts->at(k);
      nlohmann::json tex;
      if (t.is_object()) {
        t.check_keys({"file", "offset", "scale"});
        tex = {{"file", abs(t.at("file").existing_file())}, {"offset", t.number_or("offset", 0.0)}, {"scale", t.number_or("scale", 1.0)}};
      } else {
        tex = abs(t.existing_file());
      }
      nlohmann::json* l = find_layer(k);
      if (!l) t.fail("the preset has no fluorophore \"" + k + "\" (set its concentration in \"concentrations\" first)");
      (*l)["texture"] = tex;
    }
  }
  if (auto extra = n.find("extra_fluorophores")) {
    for (size_t i = 0; i < extra->size(); ++i) {
      JsonNode l = extra->at(i);
      nlohmann::json layer = l.raw();
      // File names are the user's, relative to the user's file.
      for (const char* k : {"eem", "fluorophore"})
        if (l.has(k)) layer[k] = abs(l.at(k).existing_file());
      if (auto t = l.find("texture")) {
        if (t->is_object()) layer["texture"]["file"] = abs(t->at("file").existing_file());
        else layer["texture"] = abs(t->existing_file());
      }
      base["fluorophores"].push_back(layer);
    }
  }
  if (auto c = n.find("coating")) {
    if (c->raw().is_boolean() && !c->boolean()) {
      nlohmann::json b = base;
      mat = b;
    } else {
      c->check_keys({"ior", "roughness"});
      mat["ior"] = c->number_or("ior", mat.value("ior", 1.33), 1.0, 3.0);
      mat["roughness"] = c->number_or("roughness", mat.value("roughness", 0.2), 0.001, 1.0);
    }
  }
  // Parse the merged material; errors in it name the preset file and the merged pointer.
  JsonFile merged = JsonFile::from(mat, file.string() + " (preset as modified by " + n.file() + " " + n.path() + ")");
  JsonNode m = merged.root();
  std::string type = m.at("type").string();
  if (type == "coated") return parse_coated(m, ctx);
  if (type == "fluorescent") return parse_fluorescent(m, ctx);
  return parse_lambertian(m, ctx);
}

}  // namespace ofl
