#include "renderer/core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "renderer/core/error.h"

namespace ofl {
namespace {

std::filesystem::path folder_of(const std::filesystem::path& file) {
  return file.parent_path().empty() ? std::filesystem::path(".") : file.parent_path();
}

[[noreturn]] void fail(const std::filesystem::path& file, const std::filesystem::path& tmp, const std::string& what, int err) {
  ::unlink(tmp.c_str());
  throw InputError(file.string(), "", what + (err ? std::string(": ") + std::strerror(err) : std::string()));
}

// fsync + close of a temporary, both checked (NFS and full file systems report late).
void finish(int fd, const std::filesystem::path& file, const std::filesystem::path& tmp) {
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
    int e = errno;
    ::close(fd);
    fail(file, tmp, "cannot write", e);
  }
  if (::close(fd) != 0) fail(file, tmp, "cannot write", errno);
}

void rename_into_place(const std::filesystem::path& file, const std::filesystem::path& tmp) {
  if (::rename(tmp.c_str(), file.c_str()) != 0) fail(file, tmp, "cannot rename the finished file into place", errno);
  int dfd = ::open(folder_of(file).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);  // the rename itself is durable
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

// A name that exists and is not a regular file: a folder is an error; a device or pipe
// (/dev/null, /dev/stdout, a FIFO) is written in place, since renaming over it would replace the
// device node itself. Returns true when `file` is such a special file.
bool is_special(const std::filesystem::path& file) {
  std::error_code ec;
  auto st = std::filesystem::status(file, ec);
  if (ec || !std::filesystem::exists(st)) return false;
  if (std::filesystem::is_directory(st)) throw InputError(file.string(), "", "cannot write: it is a folder");
  return !std::filesystem::is_regular_file(st);
}

void write_all(int fd, const std::string& contents, const std::filesystem::path& file, const std::filesystem::path& tmp) {
  const char* p = contents.data();
  size_t left = contents.size();
  while (left > 0) {
    ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      int e = n < 0 ? errno : ENOSPC;
      ::close(fd);
      if (tmp.empty()) throw InputError(file.string(), "", std::string("cannot write: ") + std::strerror(e));
      fail(file, tmp, "cannot write", e);
    }
    p += n;
    left -= size_t(n);
  }
}

// Runs a library's writer on the temporary `tmp`; any error names `file` (the user only knows the
// final name) and removes the temporary.
void run_writer(const std::filesystem::path& file, const std::filesystem::path& tmp,
                const std::function<void(const std::filesystem::path&)>& write) {
  try {
    write(tmp);
  } catch (const InputError& e) {
    std::string what = e.what();
    for (size_t at; (at = what.find(tmp.string())) != std::string::npos;) what.replace(at, tmp.string().size(), file.string());
    ::unlink(tmp.c_str());
    throw InputError(file.string(), e.field(), what);
  } catch (...) {
    ::unlink(tmp.c_str());
    throw;
  }
}

// A device or pipe (/dev/null, /dev/stdout, a FIFO) for a library that writes by name: the library
// may seek and read its file back (libmatio, write_mat_file's check), which a device cannot do, so
// it writes a temporary in the system's temporary folder, whose bytes then go to the device in place.
void write_special_via_temporary(const std::filesystem::path& file,
                                 const std::function<void(const std::filesystem::path&)>& write) {
  const auto tmp = std::filesystem::temp_directory_path() / temporary_for(file).filename();
  run_writer(file, tmp, write);
  std::string bytes;
  int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(file, tmp, "cannot write", errno);
  char buf[1 << 16];
  for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      int e = errno;
      ::close(fd);
      fail(file, tmp, "cannot write", e);
    }
    bytes.append(buf, size_t(n));
  }
  ::close(fd);
  ::unlink(tmp.c_str());
  write_file_atomic(file, bytes);
}

}  // namespace

std::filesystem::path temporary_for(const std::filesystem::path& file) {
  std::string name(1, '.');
  name.append(file.filename().string()).append(1, '.').append(host_tag()).append(1, '.').append(std::to_string(::getpid())).append(".tmp");
  return folder_of(file) / name;
}

std::string host_tag() {
  char h[256] = "";
  ::gethostname(h, sizeof h - 1);
  std::string s = h;
  for (char& c : s)
    if (c == '.' || c == '/') c = '_';
  return s.empty() ? "host" : s;
}

void write_file_atomic(const std::filesystem::path& file, const std::string& contents) {
  if (is_special(file)) {
    int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) throw InputError(file.string(), "", std::string("cannot write: ") + std::strerror(errno));
    write_all(fd, contents, file, {});
    if (::close(fd) != 0) throw InputError(file.string(), "", std::string("cannot write: ") + std::strerror(errno));
    return;
  }
  const auto tmp = temporary_for(file);
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(file.string(), "", std::string("cannot write: ") + std::strerror(errno));
  write_all(fd, contents, file, tmp);
  finish(fd, file, tmp);  // the data reaches the disk before the name does
  rename_into_place(file, tmp);
}

void write_via_temporary(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& write) {
  if (is_special(file)) {
    write_special_via_temporary(file, write);
    return;
  }
  const auto tmp = temporary_for(file);
  run_writer(file, tmp, write);
  int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(file, tmp, "cannot write", errno);
  finish(fd, file, tmp);
  rename_into_place(file, tmp);
}

}  // namespace ofl
