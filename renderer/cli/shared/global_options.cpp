#include "renderer/cli/shared/commands.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

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

namespace {

// "" when `s` is a finite number for which `ok` holds, else what is wrong with it.
std::string check_finite(const std::string& s, const std::function<bool(double)>& ok, const std::string& expected) {
  char* end = nullptr;
  errno = 0;
  double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v) || errno == ERANGE || !ok(v))
    return "must be " + expected + ", found \"" + s + "\"";
  return {};
}

std::string number_text(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

}  // namespace

CLI::Validator finite_range(double lo, double hi) {
  const std::string expected = "a number from " + number_text(lo) + " to " + number_text(hi);
  return CLI::Validator(
      [lo, hi, expected](std::string& s) { return check_finite(s, [&](double v) { return v >= lo && v <= hi; }, expected); },
      "FLOAT in [" + number_text(lo) + " - " + number_text(hi) + "]");
}

CLI::Validator finite_positive() {
  return CLI::Validator([](std::string& s) { return check_finite(s, [](double v) { return v > 0; }, "a number above 0"); },
                        "POSITIVE");
}

}  // namespace ofl
