// Placeholder registration for `oralfluor mesh` while the command is being built.
#include "renderer/cli/commands.h"
#include "renderer/core/error.h"

namespace ofl {
void register_mesh_command(CLI::App& app) {
  app.add_subcommand("mesh", "(under construction)")->callback([] { throw std::runtime_error("mesh: under construction"); });
}
}  // namespace ofl
