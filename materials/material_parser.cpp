#include "materials/material_parser.h"

#include <algorithm>
#include <sstream>

#include "renderer/core/errors/error.h"

namespace ofl {

AlbedoCheck photon_albedo_check(const Material& m, const std::vector<GridEem>& eems, const std::vector<Texture>& textures,
                                const WavelengthGrid& grid) {
  auto max_tex = [&](int t) {
    if (t < 0) return 1.0;
    return static_cast<double>(*std::max_element(textures[t].texels.begin(), textures[t].texels.end()));
  };
  int N = grid.size();
  std::vector<double> a(N, 0.0);
  double rscale = max_tex(m.reflectance_texture);
  for (int i = 0; i < N; ++i) a[i] = m.reflectance[i] * rscale;
  // Largest concentration factor a fluorophore's texture can give.
  auto max_factor = [&](const FluorophoreLayer& f) {
    if (f.texture < 0) return 1.0;
    double m = 0;
    for (float t : textures[f.texture].texels) m = std::max(m, f.factor(t));
    return m;
  };
  for (auto& f : m.fluorophores) {
    auto pa = eems[f.eem].photon_albedo();
    double c = f.concentration * max_factor(f);
    for (int i = 0; i < N; ++i) a[i] += c * pa[i];
  }
  if (!m.layer_out.empty()) {
    // Through an absorbing layer: T_in(ex) [R T_out + sum Phi T_out(em)]; never above the bare value.
    for (int ex = 0; ex < N; ++ex) {
      double s = m.reflectance[ex] * rscale * m.layer_out[ex];
      for (auto& f : m.fluorophores) {
        double c = f.concentration * max_factor(f);
        for (int em = ex + 1; em < N; ++em) s += c * eems[f.eem].at(em, ex) * grid.step_nm * m.layer_out[em];
      }
      a[ex] = m.layer_in[ex] * s;
    }
  }
  AlbedoCheck r;
  for (int i = 0; i < N; ++i)
    if (a[i] > r.max_albedo) { r.max_albedo = a[i]; r.at_nm = grid.wavelength(i); }
  return r;
}

Material parse_material(const std::string& name, const JsonNode& n, MaterialContext& ctx) {
  std::string type = n.at("type").string();
  Material m;
  if (type == "lambertian") m = parse_lambertian(n, ctx);
  else if (type == "fluorescent") m = parse_fluorescent(n, ctx);
  else if (type == "coated") m = parse_coated(n, ctx);
  else if (type == "tissue") m = parse_tissue(n, ctx);
  else if (type == "teeth") m = parse_tissue(n, ctx, "teeth");
  else if (type == "layered_tissue") m = parse_layered_tissue(n, ctx);
  else if (type == "regions") m = parse_regions(n, ctx);
  else n.at("type").fail("unknown material type \"" + type + "\" (expected lambertian, fluorescent, coated, tissue, teeth, layered_tissue, regions)");
  m.name = name;
  AlbedoCheck c = photon_albedo_check(m, *ctx.eems, *ctx.textures, ctx.grid);
  if (c.max_albedo > 1.0 + 1e-9) {
    // An EEM that creates energy on its own (photon albedo above 1 at unit concentration) is the
    // EEM file's fault, whatever the material does with it: name that file.
    for (const auto& f : m.fluorophores) {
      const GridEem& e = (*ctx.eems)[f.eem];
      if (e.source.empty()) continue;
      auto pa = e.photon_albedo();
      auto worst = std::max_element(pa.begin(), pa.end());
      if (worst == pa.end() || !(*worst > 1.0 + 1e-9)) continue;
      std::ostringstream s;
      s << "photon albedo (quantum yield) of this EEM is " << *worst << " > 1 at excitation "
        << ctx.grid.wavelength(int(worst - pa.begin())) << " nm (used by material \"" << name << "\" at " << n.file() << " "
        << n.path() << ")";
      throw InputError(e.source, "", s.str());
    }
    std::ostringstream s;
    s << "creates energy: photon albedo R + sum c * integral Phi = " << c.max_albedo << " > 1 at excitation " << c.at_nm
      << " nm (lower the reflectance or the concentrations)";
    n.fail(s.str());
  }
  return m;
}

}  // namespace ofl
