#include "renderer/core/error.h"

namespace ofl {

std::string InputError::describe() const {
  std::string s;
  if (!file_.empty()) s += file_ + ": ";
  if (!field_.empty()) s += field_ + ": ";
  return s + what();
}

std::string printable(const std::string& text, size_t max_chars) {
  static const char* hex = "0123456789abcdef";
  std::string out;
  size_t shown = 0;
  for (unsigned char c : text) {
    if (shown == max_chars) return out + "...";
    if (c >= 0x20 && c < 0x7f) out += char(c);
    else out.append("\\x").append(1, hex[c >> 4]).append(1, hex[c & 15]);
    ++shown;
  }
  return out;
}

}  // namespace ofl
