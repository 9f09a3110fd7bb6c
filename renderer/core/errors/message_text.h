// Making text printable for the one-line messages the CLI prints (see also printable() in error.h,
// which also cuts long text taken from a file).
#pragma once
#include <string>

namespace ofl {

// The whole of a message made one line: control characters and bytes that are not well-formed
// UTF-8 become "\xNN"; readable text (including non-ASCII file names) is kept. InputError::describe()
// and the CLI apply it to every message they print, so a corrupt file's bytes never reach the terminal.
std::string one_line(const std::string& text);

}  // namespace ofl
