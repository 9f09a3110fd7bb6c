#include "renderer/core/errors/error.h"
#include "renderer/core/errors/message_text.h"

namespace ofl {

std::string InputError::describe() const {
  std::string s;
  if (!file_.empty()) s += file_ + ": ";
  if (!field_.empty()) s += field_ + ": ";
  return one_line(s + what());
}

std::string one_line(const std::string& text) {
  static const char* hex = "0123456789abcdef";
  std::string out;
  const size_t n = text.size();
  for (size_t i = 0; i < n;) {
    unsigned char c = text[i];
    // Length of a well-formed UTF-8 sequence starting here (0: not one).
    size_t len = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
    if (len > 1 && (i + len > n || (len == 2 && c < 0xc2))) len = 0;
    for (size_t k = 1; k < len; ++k)
      if ((static_cast<unsigned char>(text[i + k]) & 0xc0) != 0x80) len = 0;
    if (len == 1 && (c < 0x20 || c == 0x7f)) len = 0;
    if (len == 0) {
      out.append("\\x").append(1, hex[c >> 4]).append(1, hex[c & 15]);
      ++i;
    } else {
      out.append(text, i, len);
      i += len;
    }
  }
  return out;
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
