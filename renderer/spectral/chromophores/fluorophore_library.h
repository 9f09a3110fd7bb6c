// The shipped fluorophore library (assets/fluorophores/<name>.json + data) and loading of any
// fluorophore onto the transport grid. A library entry is normalised so that its largest photon
// albedo (photons re-emitted per absorbed-and-incident photon, integrated over emission) is 1;
// a material's concentration c then is the photon albedo of that fluorophore at its excitation
// peak. User EEM files are used as written (absolute units) unless they ask for normalisation.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "renderer/spectral/chromophores/eem.h"

namespace ofl {

struct FluorophoreEntry {
  std::string name;
  std::string description;
  std::string citation;
  std::filesystem::path sidecar;  // the .json
};

// Every entry of assets/fluorophores, sorted by name.
std::vector<FluorophoreEntry> fluorophore_library();

// `what` is a library name ("FAD"), a sidecar .json, or an EEM matrix .csv (relative paths are
// resolved against `base_dir`). `normalise` applies to .csv files only (sidecars say themselves).
GridEem load_fluorophore(const std::string& what, const WavelengthGrid& grid,
                         const std::filesystem::path& base_dir = {}, bool normalise_csv = false);

// Scale that makes the largest column integral (over emission, Stokes-masked) of a raw EEM 1.
double max_photon_albedo(const Eem& eem);

}  // namespace ofl
