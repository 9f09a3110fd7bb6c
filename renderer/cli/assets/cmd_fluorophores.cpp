// `oralfluor fluorophores`: lists the shipped fluorophore library with peak excitation and
// emission on the chosen wavelength grid.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "renderer/cli/shared/commands.h"
#include "renderer/spectral/chromophores/fluorophore_library.h"

namespace ofl {

void register_fluorophores_command(CLI::App& app) {
  struct Opts {
    bool json = false;
    double min_nm = 350, max_nm = 830, step_nm = 5;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("fluorophores", "list the fluorophore library (peak excitation and emission)");
  cmd->add_flag("--json", o->json, "print JSON");
  cmd->add_option("--grid-min", o->min_nm, "wavelength grid start (nm)");
  cmd->add_option("--grid-max", o->max_nm, "wavelength grid end (nm)");
  cmd->add_option("--grid-step", o->step_nm, "wavelength grid step (nm)");
  cmd->callback([o] {
    WavelengthGrid grid{o->min_nm, o->max_nm, o->step_nm};
    nlohmann::json out = nlohmann::json::array();
    if (!o->json) std::printf("%-16s %10s %10s  %s\n", "name", "peak ex", "peak em", "description");
    for (auto& e : fluorophore_library()) {
      GridEem g = load_fluorophore(e.sidecar.string(), grid);
      EemPeaks p = find_peaks(g);
      if (o->json)
        out.push_back({{"name", e.name}, {"peak_excitation_nm", p.excitation_nm}, {"peak_emission_nm", p.emission_nm},
                       {"description", e.description}, {"citation", e.citation}, {"file", e.sidecar.string()}});
      else
        std::printf("%-16s %7.0f nm %7.0f nm  %s\n", e.name.c_str(), p.excitation_nm, p.emission_nm, e.description.c_str());
    }
    if (o->json) std::printf("%s\n", out.dump(2).c_str());
  });
}

}  // namespace ofl
