#include "renderer/core/files/atomic_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "renderer/core/errors/error.h"

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

void write_all(int fd, const char* p, size_t left, const std::filesystem::path& file, const std::filesystem::path& tmp) {
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

// An in-memory file a library can open by name: a memfd (/proc/self/fd/N), or where the kernel or
// /proc does not offer one, a private file in the system's temporary folder. Closed (and removed)
// on destruction.
class ScratchFile {
 public:
  explicit ScratchFile(const std::filesystem::path& file) {
    fd_ = ::memfd_create("oralfluor-write", MFD_CLOEXEC);
    if (fd_ >= 0) {
      name_ = "/proc/self/fd/" + std::to_string(fd_);
      if (::access(name_.c_str(), W_OK) == 0) return;
      ::close(fd_);
    }
    std::string tmpl = (std::filesystem::temp_directory_path() / ".oralfluor-write-XXXXXX").string();
    fd_ = ::mkostemp(tmpl.data(), O_CLOEXEC);
    if (fd_ < 0) throw InputError(file.string(), "", std::string("cannot write: no scratch file for the writer: ") + std::strerror(errno));
    name_ = tmpl;
    on_disk_ = true;
  }
  ~ScratchFile() {
    ::close(fd_);
    if (on_disk_) ::unlink(name_.c_str());
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  const std::string& name() const { return name_; }

  // Everything the library left in the file (it may have reopened it by name: the size is the
  // file's, not what this descriptor wrote), passed to `use` as one mapped block.
  void with_bytes(const std::filesystem::path& file, const std::function<void(const char*, size_t)>& use) const {
    struct stat st {};
    if (::fstat(fd_, &st) != 0) throw InputError(file.string(), "", std::string("cannot write: ") + std::strerror(errno));
    const size_t n = size_t(st.st_size);
    if (n == 0) return use("", 0);
    void* p = ::mmap(nullptr, n, PROT_READ, MAP_PRIVATE, fd_, 0);
    if (p == MAP_FAILED) throw InputError(file.string(), "", std::string("cannot write: ") + std::strerror(errno));
    try {
      use(static_cast<const char*>(p), n);
    } catch (...) {
      ::munmap(p, n);
      throw;
    }
    ::munmap(p, n);
  }

 private:
  int fd_ = -1;
  std::string name_;
  bool on_disk_ = false;
};

// Runs a library's writer on the scratch file `name`; any error names `file` (the user only knows
// the final name).
void run_writer(const std::filesystem::path& file, const std::string& name,
                const std::function<void(const std::filesystem::path&)>& write) {
  try {
    write(name);
  } catch (const InputError& e) {
    std::string what = e.what();
    for (size_t at; (at = what.find(name)) != std::string::npos;) what.replace(at, name.size(), file.string());
    throw InputError(file.string(), e.field(), what);
  }
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

void write_bytes_atomic(const std::filesystem::path& file, const char* data, size_t size) {
  if (is_special(file)) {
    int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) throw InputError(file.string(), "", std::string("cannot write: ") + std::strerror(errno));
    write_all(fd, data, size, file, {});
    if (::close(fd) != 0) throw InputError(file.string(), "", std::string("cannot write: ") + std::strerror(errno));
    return;
  }
  const auto tmp = temporary_for(file);
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(file.string(), "", std::string("cannot write: ") + std::strerror(errno));
  write_all(fd, data, size, file, tmp);
  finish(fd, file, tmp);  // the data reaches the disk before the name does
  rename_into_place(file, tmp);
}

void write_file_atomic(const std::filesystem::path& file, const std::string& contents) {
  write_bytes_atomic(file, contents.data(), contents.size());
}

std::string file_size_limit_note() {
  struct rlimit rl {};
  if (::getrlimit(RLIMIT_FSIZE, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY) return "";
  return " (files are limited to " + std::to_string(static_cast<unsigned long long>(rl.rlim_cur)) + " bytes here: ulimit -f)";
}

// The in-memory file cannot run out of room, but a file size limit stops it as it stops any file,
// and a library may not notice: output that reached the limit is taken as cut there.
void check_below_size_limit(const std::filesystem::path& file, size_t n) {
  struct rlimit rl {};
  if (::getrlimit(RLIMIT_FSIZE, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY && n >= rl.rlim_cur)
    throw InputError(file.string(), "", "cannot write: the file would be larger than the file size limit" + file_size_limit_note());
}

std::string bytes_via_memory_file(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& write) {
  std::string out;
  ScratchFile scratch(file);
  run_writer(file, scratch.name(), write);
  scratch.with_bytes(file, [&](const char* data, size_t n) {
    check_below_size_limit(file, n);
    out.assign(data, n);
  });
  return out;
}

void write_via_memory_file(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& write) {
  is_special(file);  // a folder under the name fails before the library does any work
  ScratchFile scratch(file);
  run_writer(file, scratch.name(), write);
  scratch.with_bytes(file, [&](const char* data, size_t n) {
    check_below_size_limit(file, n);
    write_bytes_atomic(file, data, n);
  });
}

}  // namespace ofl
