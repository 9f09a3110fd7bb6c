#include "renderer/cli/commands.h"

namespace ofl {
GlobalOptions& global_options() {
  static GlobalOptions g;
  return g;
}
}  // namespace ofl
