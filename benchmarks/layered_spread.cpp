// How far light travels sideways in the shipped layered presets: the position-free walk returns
// light where it entered, which holds when the pixel footprint is larger than this spread
// (docs/layered-tissue.md). For each preset and wavelength the stack is run as an MCML slab
// (normally incident pencil beam, renderer/validation/references/mcml.h) and the radius holding 90 % of the
// diffuse reflectance is reported with the diffuse reflectance itself.
//   usage: layered_spread [--photons N] [--json]
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "renderer/validation/references/mcml.h"
#include "renderer/core/files/json_node.h"
#include "renderer/render/integrator/render_tables.h"

using namespace ofl;

namespace {

// The preset's stack at one grid bin as an MCML input (fluorophores absorb, at their full amount;
// a semi-infinite last layer becomes 50 mm thick).
McmlInput preset_slab(const std::string& preset, double nm) {
  nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                      {"integrator", {{"wavelengths", {{"min_nm", 350}, {"max_nm", 750}, {"step_nm", 5}}}}},
                      {"camera", {{"position", {0, 0, 1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 10}, {"resolution", {4, 4}}}},
                      {"materials", {{"m", {{"type", "layered_tissue"}, {"preset", preset}, {"transport", "walk"}}}}},
                      {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {1, 0, 0}}, {"v", {0, 1, 0}}, {"material", "m"}}}}};
  Scene sc = load_scene(JsonFile::from(j, preset + ".json"));
  RenderTables t(sc);
  const StackTables& st = t.materials[0].stack;
  const int bin = sc.grid().index_of(nm);
  McmlInput in;
  in.name = preset;
  in.dz_cm = 0.001;
  in.dr_cm = 0.001;
  in.nz = 200;
  in.nr = 500;
  in.na = 1;
  in.n_above = st.ambient_ior;
  for (const StackLayerTables& L : st.layers) {
    McmlLayer m;
    m.n = L.ior;
    double mua = L.mua[bin];
    for (const auto& f : L.fluors) mua += f.absorb[bin];
    m.mua_per_cm = 10.0 * mua;
    m.mus_per_cm = 10.0 * L.mus[bin];
    m.g = L.g;
    m.d_cm = std::isfinite(L.bottom) ? 0.1 * (L.bottom - L.top) : 5.0;
    in.layers.push_back(m);
  }
  in.n_below = st.layers.back().ior;
  return in;
}

}  // namespace

int main(int argc, char** argv) {
  long long photons = 100000;
  bool json = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--photons" && i + 1 < argc) photons = std::stoll(argv[++i]);
    else if (a == "--json") json = true;
  }
  nlohmann::json out = nlohmann::json::array();
  if (!json) {
    std::printf("| preset | wavelength | diffuse reflectance Rd | r90 (mm) |\n|---|---|---|---|\n");
  }
  for (const char* p : {"lateral_tongue", "dorsal_tongue", "dorsal_tongue_coated", "buccal_mucosa", "dysplasia",
                        "leukoplakia", "blood_spot"})
    for (double nm : {385.0, 405.0, 450.0, 550.0, 630.0}) {
      SlabResult r = simulate_slab(preset_slab(p, nm), photons, 3);
      out.push_back({{"preset", p}, {"nm", nm}, {"rd", r.rd}, {"r90_mm", r.r90_mm}});
      if (!json) std::printf("| %s | %.0f nm | %.3f | %.2f |\n", p, nm, r.rd, r.r90_mm);
      std::fflush(stdout);
    }
  if (json) std::printf("%s\n", out.dump(1).c_str());
  return 0;
}
