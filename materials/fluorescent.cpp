// {"type": "fluorescent", "reflectance": <spectrum>, "fluorophores": [layer, ...]} with a layer
//   {"name": "FAD", "concentration": 0.02, "texture": "map.png"}       library fluorophore
//   "texture": {"file": "lesion.png", "offset": 1, "scale": -0.5}     factor = offset + scale * texel
//   {"eem": "my_eem.csv", "concentration": 1.0, "normalise": false}    EEM matrix file (absolute
//                                                                      units unless normalised)
//   {"fluorophore": "my.json", ...}                                     sidecar like the library's
// The concentration of a library fluorophore is its photon albedo at its excitation peak; a
// texture multiplies it per UV.
#include <algorithm>

#include "materials/material_parser.h"
#include "renderer/core/errors/error.h"
#include "renderer/spectral/chromophores/fluorophore_library.h"

namespace ofl {

int load_texture(const JsonNode& n, MaterialContext& ctx) {
  auto path = n.existing_file();
  std::string key = std::filesystem::weakly_canonical(path).string();
  if (auto it = ctx.texture_index.find(key); it != ctx.texture_index.end()) return it->second;
  ctx.textures->push_back(n.read_file([](const std::filesystem::path& p) { return read_texture(p); }));
  int idx = static_cast<int>(ctx.textures->size()) - 1;
  ctx.texture_index[key] = idx;
  return idx;
}

int load_fluorophore_eem(const JsonNode& f, MaterialContext& ctx, std::string* name) {
  int given = f.has("name") + f.has("eem") + f.has("fluorophore");
  if (given != 1) f.fail("give exactly one of name (library), eem (matrix CSV) or fluorophore (sidecar JSON)");
  std::string key, what;
  bool normalise = f.boolean_or("normalise", false);
  std::filesystem::path base = std::filesystem::path(f.file()).parent_path();
  if (f.has("name")) {
    what = f.at("name").string();
    key = "lib:" + what;
  } else {
    JsonNode p = f.has("eem") ? f.at("eem") : f.at("fluorophore");
    what = p.existing_file().string();
    key = std::filesystem::weakly_canonical(what).string() + (normalise ? "#n" : "");
  }
  if (name) *name = f.has("name") ? what : std::filesystem::path(what).stem().string();
  auto it = ctx.eem_index.find(key);
  if (it == ctx.eem_index.end()) {
    try {
      ctx.eems->push_back(load_fluorophore(what, ctx.grid, base, normalise));
    } catch (const InputError& e) {
      // Keep the original file when the problem is inside the EEM file (and say which entry named
      // it); otherwise name this field.
      if (!e.file().empty())
        throw InputError(e.file(), e.field(), std::string(e.what()) + " (named by " + f.file() + " " + f.path() + ")");
      f.fail(e.field() + ": " + e.what());
    }
    it = ctx.eem_index.emplace(key, static_cast<int>(ctx.eems->size()) - 1).first;
  }
  return it->second;
}

void parse_fluorophore_texture(const JsonNode& t, MaterialContext& ctx, int* texture, double* offset, double* scale) {
  if (t.is_object()) {
    t.check_keys({"file", "offset", "scale"});
    *texture = load_texture(t.at("file"), ctx);
    *offset = t.number_or("offset", 0.0, -1e3, 1e3);
    *scale = t.number_or("scale", 1.0, -1e3, 1e3);
  } else {
    *texture = load_texture(t, ctx);
  }
}

std::vector<FluorophoreLayer> parse_fluorophore_layers(const JsonNode& list, MaterialContext& ctx) {
  std::vector<FluorophoreLayer> out;
  if (list.size() > size_t(kMaxFluorophoresPerMaterial))
    list.fail("has " + std::to_string(list.size()) + " fluorophores; a material may have at most " +
              std::to_string(kMaxFluorophoresPerMaterial));
  for (size_t i = 0; i < list.size(); ++i) {
    JsonNode f = list.at(i);
    f.check_keys({"name", "eem", "fluorophore", "concentration", "texture", "normalise"});
    FluorophoreLayer layer;
    layer.eem = load_fluorophore_eem(f, ctx, &layer.name);
    layer.concentration = f.at("concentration").number(0.0, 1.0);
    if (auto t = f.find("texture")) parse_fluorophore_texture(*t, ctx, &layer.texture, &layer.texture_offset, &layer.texture_scale);
    out.push_back(layer);
  }
  return out;
}

Material parse_fluorescent(const JsonNode& n, MaterialContext& ctx) {
  n.check_keys({"type", "reflectance", "fluorophores", "emission", "reflectance_texture"});
  Material m;
  m.reflectance = n.find("reflectance") ? parse_reflectance(n.at("reflectance"), ctx.grid)
                                        : std::vector<double>(ctx.grid.size(), 0.0);
  m.fluorophores = parse_fluorophore_layers(n.at("fluorophores"), ctx);
  if (auto e = n.find("emission")) m.emission = parse_emission(*e, ctx.grid);
  if (auto t = n.find("reflectance_texture")) m.reflectance_texture = load_texture(*t, ctx);
  return m;
}

}  // namespace ofl
