// {"type": "regions", "base": "tongue_healthy",
//  "regions": [{"mask": "lesion.png", "material": "dysplasia", "threshold": 0.5}, ...]}
// A surface made of several scene materials side by side: at each surface point the first region
// whose grayscale mask (looked up at the point's UV) exceeds its threshold gives the material,
// otherwise the base does. Lesions and blood spots are painted this way on one mesh; the image's
// material plane (aov.material) then names the material actually seen, so ROIs can be chosen by it.
#include "materials/material_parser.h"

namespace ofl {

Material parse_regions(const JsonNode& n, MaterialContext& ctx) {
  n.check_keys({"type", "base", "regions"});
  Material m;
  m.regions_base_name = n.at("base").string();
  JsonNode list = n.at("regions");
  if (list.size() == 0) list.fail("needs at least one region");
  for (size_t i = 0; i < list.size(); ++i) {
    JsonNode r = list.at(i);
    r.check_keys({"mask", "material", "threshold"});
    MaterialRegion reg;
    reg.texture = load_texture(r.at("mask"), ctx);
    reg.material_name = r.at("material").string();
    reg.threshold = r.number_or("threshold", 0.5, 0.0, 1.0);
    m.regions.push_back(reg);
  }
  m.reflectance.assign(ctx.grid.size(), 0.0);
  return m;
}

}  // namespace ofl
