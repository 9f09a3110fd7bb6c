#include "renderer/sweep/sweep_store.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "renderer/core/error.h"

namespace ofl {
namespace {

std::string hostname() {
  char h[256] = "";
  ::gethostname(h, sizeof h - 1);
  std::string s = h;
  for (char& c : s)
    if (c == '.' || c == '/') c = '_';
  return s.empty() ? "host" : s;
}

void fsync_path(const std::filesystem::path& p, int flags) {
  int fd = ::open(p.c_str(), flags);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

void write_file_atomic(const std::filesystem::path& file, const std::string& contents) {
  auto dir = file.parent_path().empty() ? std::filesystem::path(".") : file.parent_path();
  std::string name(1, '.');
  name.append(file.filename().string()).append(1, '.').append(hostname()).append(1, '.').append(std::to_string(::getpid())).append(".tmp");
  auto tmp = dir / name;
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(tmp.string(), "", std::string("cannot write: ") + std::strerror(errno));
  const char* p = contents.data();
  size_t left = contents.size();
  while (left > 0) {
    ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      int e = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      throw InputError(tmp.string(), "", std::string("cannot write: ") + std::strerror(e));
    }
    p += n;
    left -= size_t(n);
  }
  ::fsync(fd);  // the data reaches the disk before the name does
  ::close(fd);
  if (::rename(tmp.c_str(), file.c_str()) != 0) {
    int e = errno;
    ::unlink(tmp.c_str());
    throw InputError(file.string(), "", std::string("cannot rename into place: ") + std::strerror(e));
  }
  fsync_path(dir, O_RDONLY | O_DIRECTORY);  // and the rename itself is durable
}

PointStore::PointStore(std::filesystem::path out_dir, bool create) : dir_(std::move(out_dir) / "points") {
  std::error_code ec;
  if (!create) return;
  std::filesystem::create_directories(dir_, ec);
  if (!std::filesystem::is_directory(dir_, ec)) throw InputError(dir_.string(), "", "cannot create the points folder");
}

std::filesystem::path PointStore::file_for(const std::string& key) const { return dir_ / (key + ".json"); }

std::optional<nlohmann::ordered_json> PointStore::load(const std::string& key) const {
  std::ifstream in(file_for(key), std::ios::binary);
  if (!in) return std::nullopt;
  try {
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(in);
    if (j.value("key", std::string()) != key) return std::nullopt;
    return j;
  } catch (const std::exception&) {
    return std::nullopt;  // cannot happen for files this store wrote; recompute rather than fail
  }
}

void PointStore::save(const std::string& key, const nlohmann::ordered_json& result) const {
  write_file_atomic(file_for(key), result.dump(1) + "\n");
}

int PointStore::remove_stale_temporaries() const { return ofl::remove_stale_temporaries(dir_); }

int remove_stale_temporaries(const std::filesystem::path& dir) {
  const std::string host = std::string(1, '.').append(hostname()).append(1, '.');
  int removed = 0;
  std::error_code ec;
  for (auto& e : std::filesystem::directory_iterator(dir, ec)) {
    std::string n = e.path().filename().string();
    if (n.size() < 5 || n[0] != '.' || n.substr(n.size() - 4) != ".tmp") continue;
    size_t h = n.find(host);
    if (h == std::string::npos) continue;  // another host's temporary: not ours to judge
    std::string pid_s = n.substr(h + host.size(), n.size() - 4 - h - host.size());
    char* end = nullptr;
    long pid = std::strtol(pid_s.c_str(), &end, 10);
    if (pid_s.empty() || *end != '\0' || pid <= 0) continue;
    if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // its writer may still be running
    std::filesystem::remove(e.path(), ec);
    ++removed;
  }
  return removed;
}

std::vector<std::string> PointStore::keys() const {
  std::vector<std::string> k;
  std::error_code ec;
  for (auto& e : std::filesystem::directory_iterator(dir_, ec)) {
    std::string n = e.path().filename().string();
    if (n.size() > 5 && n[0] != '.' && n.substr(n.size() - 5) == ".json") k.push_back(n.substr(0, n.size() - 5));
  }
  return k;
}

}  // namespace ofl
