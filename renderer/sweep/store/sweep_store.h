// Where finished design points live: one JSON file per point, <dir>/points/<key>.json, named by
// the point's content key (sweep_point.h). A file is written to a temporary name beside it,
// flushed to disk, then renamed over the final name, so at any moment - SIGKILL, power loss - a
// point file either does not exist or is complete; a rerun recomputes exactly the points whose file
// is missing. Temporaries left by a killed process are named .<key>.json.<host>.<pid>.tmp and are
// removed by the next run on the same host once that process is gone (another shard's live
// temporary is never touched).
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/core/files/atomic_file.h"

namespace ofl {

// Removes the temporaries write_file_atomic left in `dir` when its process died (this host's
// only, and only once that process is gone); returns how many.
int remove_stale_temporaries(const std::filesystem::path& dir);

class PointStore {
 public:
  // Creates <out_dir>/points unless `create` is false (a dry run only looks).
  explicit PointStore(std::filesystem::path out_dir, bool create = true);
  const std::filesystem::path& dir() const { return dir_; }
  std::filesystem::path file_for(const std::string& key) const;
  // The stored result when its file exists, parses and carries this key; nullopt otherwise.
  std::optional<nlohmann::ordered_json> load(const std::string& key) const;
  // Cheap (two small reads, no parse, so a dry run of a large design stays fast): the file exists,
  // names this key in its first 256 bytes (every result starts with format, version and key) and
  // ends like a whole JSON document. Writes are atomic, so only damage from outside makes has() and load() differ.
  bool has(const std::string& key) const;
  void save(const std::string& key, const nlohmann::ordered_json& result) const;
  // Removes temporaries of dead processes on this host; returns how many.
  int remove_stale_temporaries() const;
  std::vector<std::string> keys() const;  // every stored key (including points of other designs)

 private:
  std::filesystem::path dir_;
};

}  // namespace ofl
