#include "renderer/cli/commands.h"

namespace ofl {
GlobalOptions& global_options() {
  static GlobalOptions g;
  return g;
}

CLI::Validator uint64_validator() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        static const std::string kMax = "18446744073709551615";
        if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos)
          return "must be a whole number from 0 to " + kMax + ", found \"" + s + "\"";
        std::string d = s.substr(std::min(s.find_first_not_of('0'), s.size() - 1));
        if (d.size() > kMax.size() || (d.size() == kMax.size() && d > kMax))
          return "must be at most " + kMax + ", found " + s;
        return {};
      },
      "UINT64");
}
}  // namespace ofl
