#include "renderer/core/process/library_stderr.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cstdio>
#include <mutex>

namespace ofl {

namespace {
std::mutex& capture_mutex() {
  static std::mutex m;
  return m;
}

std::string read_all(int fd) {
  std::string out;
  char buf[4096];
  for (off_t at = 0;;) {
    ssize_t n = ::pread(fd, buf, sizeof buf, at);
    if (n <= 0) break;
    out.append(buf, size_t(n));
    at += n;
  }
  return out;
}

void write_all(int fd, const std::string& s) {
  for (size_t at = 0; at < s.size();) {
    ssize_t n = ::write(fd, s.data() + at, s.size() - at);
    if (n <= 0) return;
    at += size_t(n);
  }
}
}  // namespace

struct LibraryStderr::State {
  std::unique_lock<std::mutex> lock{capture_mutex()};
  std::vector<std::string> prefixes;
  int saved = -1, capture = -1;
  bool ended = false;
};

LibraryStderr::LibraryStderr(std::vector<std::string> prefixes) : state_(std::make_unique<State>()) {
  state_->prefixes = std::move(prefixes);
  std::fflush(stderr);
  state_->capture = ::memfd_create("oralfluor-stderr", MFD_CLOEXEC);
  if (state_->capture < 0) return;  // no capture: the library's lines reach stderr as before
  state_->saved = ::dup(2);
  if (state_->saved < 0 || ::dup2(state_->capture, 2) < 0) {
    if (state_->saved >= 0) ::close(state_->saved);
    ::close(state_->capture);
    state_->saved = state_->capture = -1;
  }
}

LibraryStderr::~LibraryStderr() {
  if (!state_->ended) end();
}

std::vector<std::string> LibraryStderr::end() {
  std::vector<std::string> library;
  state_->ended = true;
  if (state_->capture < 0) return library;
  std::fflush(stderr);
  ::dup2(state_->saved, 2);
  ::close(state_->saved);
  std::string text = read_all(state_->capture);
  ::close(state_->capture);
  state_->capture = -1;
  std::string others;
  for (size_t at = 0; at < text.size();) {
    size_t nl = text.find('\n', at);
    size_t end = nl == std::string::npos ? text.size() : nl + 1;
    std::string line = text.substr(at, end - at);
    at = end;
    bool mine = false;
    for (const auto& p : state_->prefixes) mine = mine || line.rfind(p, 0) == 0;
    if (!mine) {
      others += line;
      continue;
    }
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    library.push_back(line);
  }
  write_all(2, others);
  return library;
}

}  // namespace ofl
