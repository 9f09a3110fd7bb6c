#include "renderer/sweep/store/sweep_store.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"

namespace ofl {

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

bool PointStore::has(const std::string& key) const {
  int fd = ::open(file_for(key).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  char head[256] = {}, tail[2] = {};
  const ssize_t n = ::pread(fd, head, sizeof head, 0);
  const off_t size = ::lseek(fd, 0, SEEK_END);
  const bool tail_ok = size >= 2 && ::pread(fd, tail, 2, size - 2) == 2 && tail[0] == '}' && tail[1] == '\n';
  ::close(fd);
  const std::string start(head, n > 0 ? size_t(n) : 0);
  return tail_ok && start.rfind("{", 0) == 0 && start.find("\"key\": \"" + key + "\"") != std::string::npos;
}

void PointStore::save(const std::string& key, const nlohmann::ordered_json& result) const {
  write_file_atomic(file_for(key), result.dump(1) + "\n");
}

int PointStore::remove_stale_temporaries() const { return ofl::remove_stale_temporaries(dir_); }

int remove_stale_temporaries(const std::filesystem::path& dir) {
  const std::string host = std::string(1, '.').append(host_tag()).append(1, '.');
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
