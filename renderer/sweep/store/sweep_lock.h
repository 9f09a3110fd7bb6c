// Several sweeps writing into one output folder: two shards of one design (--shard), the same
// command started twice, an MPI job. POSIX record locks (fcntl) do the bookkeeping, so a process
// that dies - SIGKILL included - lets go of everything it held, and nothing stale is ever judged
// by host names or process ids.
//  - Folder: every sweep that computes holds <out>/.sweep.lock, shared by single-process sweeps,
//    exclusively by an MPI job (whose workers compute points rank 0 cannot claim one by one). A
//    sweep that cannot get it refuses with exit 2, naming the holder.
//  - Points: a single-process sweep claims a point before computing it by locking
//    <out>/points/.<key>.claim (holding "<host> pid <pid>"); a point another process has claimed
//    is skipped, and a claimed point whose result appears meanwhile is not computed again. So two
//    sweeps sharing a folder split the points between them, and none is computed twice.
//  - Report: written under <out>/.report.lock, from the points stored when the lock is taken, so
//    the last sweep to finish writes the report with every point.
#pragma once
#include <filesystem>
#include <string>

namespace ofl {

// "<host> pid <pid>": what a lock file says about its holder.
std::string lock_holder_text();

class FolderLock {
 public:
  enum class Mode { kShared, kExclusive };
  // Takes the lock (without waiting when `wait` is false: then InputError naming `dir` and the holder).
  FolderLock(const std::filesystem::path& dir, const std::string& name, Mode mode, bool wait, const std::string& purpose);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

class PointClaim {
 public:
  // Tries to claim the point `key` in `points_dir`; held() says whether it succeeded, holder() who
  // has it otherwise.
  PointClaim(const std::filesystem::path& points_dir, const std::string& key);
  ~PointClaim();  // releases (removes the claim file)
  PointClaim(const PointClaim&) = delete;
  PointClaim& operator=(const PointClaim&) = delete;
  bool held() const { return fd_ >= 0; }
  const std::string& holder() const { return holder_; }

 private:
  std::filesystem::path file_;
  int fd_ = -1;
  std::string holder_;
};

}  // namespace ofl
