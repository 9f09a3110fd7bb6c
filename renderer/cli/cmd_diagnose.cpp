// Placeholder registration for `oralfluor diagnose` while the command is being built.
#include "renderer/cli/commands.h"
#include "renderer/core/error.h"

namespace ofl {
void register_diagnose_command(CLI::App& app) {
  app.add_subcommand("diagnose", "(under construction)")->callback([] { throw std::runtime_error("diagnose: under construction"); });
}
}  // namespace ofl
