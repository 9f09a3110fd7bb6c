// {"type": "regions", "base": "tongue_healthy",
//  "regions": [{"mask": "lesion.png", "material": "dysplasia", "threshold": 0.5},
//              {"sphere": {"center_m": [x, y, z], "radius_mm": 2.5}, "material": "blood_spot"}, ...]}
// A surface made of several scene materials side by side: at each surface point the first region
// whose grayscale mask (looked up at the point's UV) exceeds its threshold, or whose sphere holds
// the point (a disc of that radius where the sphere cuts the surface, whatever the UVs), gives the
// material, otherwise the base does. Lesions and blood spots are painted this way on one mesh; the image's
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
    r.check_keys({"mask", "sphere", "material", "threshold"});
    MaterialRegion reg;
    if (r.has("mask") == r.has("sphere")) r.fail("give exactly one of \"mask\" (a texture) or \"sphere\" ({\"center_m\", \"radius_mm\"})");
    if (auto m = r.find("mask")) {
      reg.texture = load_texture(*m, ctx);
      reg.threshold = r.number_or("threshold", 0.5, 0.0, 1.0);
      reg.side_distance = side_distance_texels((*ctx.textures)[size_t(reg.texture)], reg.threshold);
    } else {
      if (r.has("threshold")) r.at("threshold").fail("a sphere region has no threshold");
      JsonNode sp = r.at("sphere");
      sp.check_keys({"center_m", "radius_mm"});
      const glm::dvec3 c = sp.at("center_m").vec3();
      reg.sphere = true;
      reg.centre_m[0] = c.x;
      reg.centre_m[1] = c.y;
      reg.centre_m[2] = c.z;
      reg.radius_m = sp.at("radius_mm").positive() / 1000.0;
    }
    reg.material_name = r.at("material").string();
    m.regions.push_back(reg);
  }
  m.reflectance.assign(ctx.grid.size(), 0.0);
  return m;
}

}  // namespace ofl
