// Error types and exit codes shared by every command.
// InputError is for anything the user can fix (bad file, bad field, unphysical data): the CLI
// prints it as one line "error: <file>: <field>: <what>" and exits with code 2.
#pragma once
#include <stdexcept>
#include <string>

namespace ofl {

enum ExitCode : int { kExitOk = 0, kExitInternal = 1, kExitBadInput = 2, kExitInterrupted = 130 };

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string field, const std::string& what)
      : std::runtime_error(what), file_(std::move(file)), field_(std::move(field)) {}
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }
  // "<file>: <field>: <what>", leaving out empty parts.
  std::string describe() const;

 private:
  std::string file_, field_;
};

// Text taken from an input file, made safe for a one-line message: bytes outside printable ASCII
// become "\xNN", and anything past `max_chars` is cut and marked with "...". Corrupt files never
// put raw binary bytes (or newlines) into an error message.
std::string printable(const std::string& text, size_t max_chars = 60);

// Raised when the user interrupts long work (SIGINT); finished work has been saved.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace ofl
