// Placeholder registration for `oralfluor sweep` while the command is being built.
#include "renderer/cli/commands.h"
#include "renderer/core/error.h"

namespace ofl {
void register_sweep_command(CLI::App& app) {
  app.add_subcommand("sweep", "(under construction)")->callback([] { throw std::runtime_error("sweep: under construction"); });
}
}  // namespace ofl
