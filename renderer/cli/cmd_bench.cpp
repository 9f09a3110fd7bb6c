// Placeholder registration for `oralfluor bench` while the command is being built.
#include "renderer/cli/commands.h"
#include "renderer/core/error.h"

namespace ofl {
void register_bench_command(CLI::App& app) {
  app.add_subcommand("bench", "(under construction)")->callback([] { throw std::runtime_error("bench: under construction"); });
}
}  // namespace ofl
