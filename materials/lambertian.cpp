// {"type": "lambertian", "reflectance": <spectrum 0..1>, "emission": <spectrum, W sr^-1 m^-2 nm^-1>,
//  "reflectance_texture": "map.png"}: an ideal diffuse reflector, optionally emitting uniformly.
#include "materials/material_parser.h"
#include "renderer/spectral/spectrum_json.h"

namespace ofl {

std::vector<double> parse_reflectance(const JsonNode& n, const WavelengthGrid& grid) {
  auto v = tabulate(parse_spectrum(n, SpectrumKind::kReflectance), grid);
  check_tabulated(n, v, grid, SpectrumKind::kReflectance);
  return v;
}

std::vector<double> parse_emission(const JsonNode& n, const WavelengthGrid& grid) {
  auto v = tabulate(parse_spectrum(n, SpectrumKind::kEmission), grid);
  check_tabulated(n, v, grid, SpectrumKind::kEmission);
  return v;
}

Material parse_lambertian(const JsonNode& n, MaterialContext& ctx) {
  n.check_keys({"type", "reflectance", "emission", "reflectance_texture"});
  Material m;
  m.reflectance = n.find("reflectance") ? parse_reflectance(n.at("reflectance"), ctx.grid)
                                        : std::vector<double>(ctx.grid.size(), 0.0);
  if (auto e = n.find("emission")) m.emission = parse_emission(*e, ctx.grid);
  if (auto t = n.find("reflectance_texture")) m.reflectance_texture = load_texture(*t, ctx);
  return m;
}

}  // namespace ofl
