#include "renderer/core/error.h"

namespace ofl {

std::string InputError::describe() const {
  std::string s;
  if (!file_.empty()) s += file_ + ": ";
  if (!field_.empty()) s += field_ + ": ";
  return s + what();
}

}  // namespace ofl
