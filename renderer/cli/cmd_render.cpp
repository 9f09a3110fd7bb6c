// Placeholder registration for `oralfluor render` while the command is being built.
#include "renderer/cli/commands.h"
#include "renderer/core/error.h"

namespace ofl {
void register_render_command(CLI::App& app) {
  app.add_subcommand("render", "(under construction)")->callback([] { throw std::runtime_error("render: under construction"); });
}
}  // namespace ofl
