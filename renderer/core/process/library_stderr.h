// Some libraries under OpenImageIO print their own diagnostics on stderr ("libpng error: Not enough
// image data") before OpenImageIO hands the same error back to the caller, who reports it in the
// project's one-line form (renderer/core/errors/error.h). A LibraryStderr sends file descriptor 2 to an
// in-memory file while such a call runs. When it ends, the lines that start with one of the
// library's prefixes are taken out (end() returns them; the caller reports them in its own words),
// and everything else that reached stderr meanwhile (another thread's progress line) is passed on
// to the real stderr unchanged. One capture at a time in the process: others wait.
#pragma once
#include <memory>
#include <string>
#include <vector>

namespace ofl {

class LibraryStderr {
 public:
  explicit LibraryStderr(std::vector<std::string> prefixes);
  ~LibraryStderr();  // ends the capture if end() was not called (the library's lines are dropped)
  LibraryStderr(const LibraryStderr&) = delete;
  LibraryStderr& operator=(const LibraryStderr&) = delete;

  // Restores stderr, passes the other lines on, returns the library's lines (without newlines).
  std::vector<std::string> end();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace ofl
