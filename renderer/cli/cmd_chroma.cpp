// Placeholder registration for `oralfluor chroma` while the command is being built.
#include "renderer/cli/commands.h"
#include "renderer/core/error.h"

namespace ofl {
void register_chroma_command(CLI::App& app) {
  app.add_subcommand("chroma", "(under construction)")->callback([] { throw std::runtime_error("chroma: under construction"); });
}
}  // namespace ofl
