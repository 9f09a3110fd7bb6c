#include "renderer/core/files/asset_path.h"

#include <cstdlib>

#include "renderer/core/errors/error.h"

namespace ofl {

std::filesystem::path asset_root() {
  if (const char* env = std::getenv("OFL_ASSETS"); env && *env) return env;
  return std::filesystem::path(OFL_SOURCE_DIR) / "assets";
}

std::filesystem::path asset_path(const std::string& relative) {
  auto p = asset_root() / relative;
  std::error_code ec;
  if (!std::filesystem::exists(p, ec)) throw InputError(p.string(), "", "shipped asset not found (set OFL_ASSETS?)");
  return p;
}

}  // namespace ofl
