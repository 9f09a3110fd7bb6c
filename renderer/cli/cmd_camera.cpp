// Placeholder registration for `oralfluor camera` while the command is being built.
#include "renderer/cli/commands.h"
#include "renderer/core/error.h"

namespace ofl {
void register_camera_command(CLI::App& app) {
  app.add_subcommand("camera", "(under construction)")->callback([] { throw std::runtime_error("camera: under construction"); });
}
}  // namespace ofl
