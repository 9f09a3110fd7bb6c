// Where the shipped assets (spectra, fluorophores, meshes, presets) are found at run time:
// $OFL_ASSETS if set, else the assets/ folder of the source tree the binary was built from.
#pragma once
#include <filesystem>
#include <string>

namespace ofl {

std::filesystem::path asset_root();
// asset_root() / relative; throws InputError when the file is missing.
std::filesystem::path asset_path(const std::string& relative);

}  // namespace ofl
