// {"type": "coated", "base": <lambertian or fluorescent material>, "ior": 1.33, "roughness": 0.15}:
// a Lambertian or fluorescent base under the wet coating of coated.h.
#include "materials/material_parser.h"

namespace ofl {

Material parse_coated(const JsonNode& n, MaterialContext& ctx) {
  n.check_keys({"type", "base", "ior", "roughness"});
  JsonNode b = n.at("base");
  std::string bt = b.at("type").string();
  Material m;
  if (bt == "lambertian") m = parse_lambertian(b, ctx);
  else if (bt == "fluorescent") m = parse_fluorescent(b, ctx);
  else b.at("type").fail("a coating goes over a lambertian or fluorescent base, not \"" + bt + "\"");
  if (!m.emission.empty()) b.fail("a coated base cannot emit");
  m.coating.enabled = true;
  m.coating.ior = n.number_or("ior", 1.33, 1.0, 3.0);
  m.coating.roughness = n.number_or("roughness", 0.15, 0.001, 1.0);
  return m;
}

}  // namespace ofl
