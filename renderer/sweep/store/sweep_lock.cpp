#include "renderer/sweep/store/sweep_lock.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"

namespace ofl {

namespace {

bool lock_fd(int fd, short type, bool wait) {
  struct flock fl {};
  fl.l_type = type;
  fl.l_whence = SEEK_SET;
  for (;;) {
    if (::fcntl(fd, wait ? F_SETLKW : F_SETLK, &fl) == 0) return true;
    if (errno == EINTR && wait) continue;
    return false;
  }
}

std::string read_text(int fd) {
  char b[256];
  ssize_t n = ::pread(fd, b, sizeof b - 1, 0);
  std::string s(b, n > 0 ? size_t(n) : 0);
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

void write_text(int fd, const std::string& s) {
  if (::ftruncate(fd, 0) != 0 || s.empty()) return;
  ssize_t r = ::pwrite(fd, s.data(), s.size(), 0);
  (void)r;  // the text only names the holder in messages
}

// Who holds a conflicting lock on `fd`: the holder's own text, or the pid the kernel reports.
std::string conflicting_holder(int fd, short type) {
  std::string text = read_text(fd);
  if (!text.empty()) return text;
  struct flock fl {};
  fl.l_type = type;
  fl.l_whence = SEEK_SET;
  if (::fcntl(fd, F_GETLK, &fl) == 0 && fl.l_type != F_UNLCK && fl.l_pid > 0) return "pid " + std::to_string(fl.l_pid);
  return "another process";
}

}  // namespace

std::string lock_holder_text() { return host_tag() + " pid " + std::to_string(::getpid()); }

FolderLock::FolderLock(const std::filesystem::path& dir, const std::string& name, Mode mode, bool wait,
                       const std::string& purpose) {
  const auto file = dir / name;
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(file.string(), "", std::string("cannot open the lock file: ") + std::strerror(errno));
  const short type = mode == Mode::kExclusive ? F_WRLCK : F_RDLCK;
  if (!lock_fd(fd_, type, wait)) {
    std::string holder = conflicting_holder(fd_, type);
    ::close(fd_);
    fd_ = -1;
    throw InputError(dir.string(), "", "another sweep is writing into this folder (" + holder + "); " + purpose);
  }
  // An exclusive holder of a lock others may be refused names itself for their messages; shared
  // holders and waited-for locks write nothing (nothing to spend room on when the disk is full).
  if (mode == Mode::kExclusive && !wait) write_text(fd_, lock_holder_text() + "\n");
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the lock
}

PointClaim::PointClaim(const std::filesystem::path& points_dir, const std::string& key)
    : file_(points_dir / ("." + key + ".claim")) {
  for (int attempt = 0; attempt < 8; ++attempt) {
    int fd = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) throw InputError(file_.string(), "", std::string("cannot create the claim file: ") + std::strerror(errno));
    if (!lock_fd(fd, F_WRLCK, false)) {
      holder_ = conflicting_holder(fd, F_WRLCK);
      ::close(fd);
      return;
    }
    // The previous holder removes the file when it lets go: a lock on a file that is no longer
    // under the name claims nothing; open the name again.
    struct stat a {}, b {};
    if (::fstat(fd, &a) == 0 && ::stat(file_.c_str(), &b) == 0 && a.st_ino == b.st_ino && a.st_dev == b.st_dev) {
      write_text(fd, lock_holder_text() + "\n");
      fd_ = fd;
      return;
    }
    ::close(fd);
  }
  holder_ = "another process (the claim file keeps changing)";
}

PointClaim::~PointClaim() {
  if (fd_ < 0) return;
  ::unlink(file_.c_str());  // before letting go, so nobody locks a name that is being removed
  ::close(fd_);
}

}  // namespace ofl
