// Running a sweep: which points this process computes, in what order, and where results go.
//  - The design (sweep_design.h) is the same on every process. `--shard i/N` keeps the points
//    whose design index is i mod N (for Slurm job arrays: one shard per array task).
//  - Points whose result file already exists (sweep_store.h) are skipped, so a killed sweep
//    finishes only the missing points when run again.
//  - Under mpirun the points left to do are dealt round-robin over the ranks; every rank renders,
//    workers send each finished result to rank 0 as JSON over MPI (no shared filesystem needed),
//    rank 0 stores them as they arrive and writes the report.
//  - Before anything is rendered, the scenes and cameras of every point of a small design (up to
//    kCheckAllPointsUpTo points), or of a large one the points that carry every level of every
//    parameter (and each range's smallest and largest value), are loaded, so a value the loaders
//    reject fails at once; the other points load when they run.
//  - Sizing: the count of points to compute is printed before the first, and after the first point
//    and again after the first kPointsTimed how long a point takes and what that means for the rest.
//    A dry run computes only the keys (no loading beyond the check above) and lists the points of a
//    small design, the first kDryRunListFirst of a large one, with counts.
//  - Several sweeps in one folder share the work without computing a point twice (sweep_lock.h).
//  - SIGINT/SIGTERM: in the checks before the first point the command stops at once (nothing to
//    save); during a point, that point is abandoned (nothing partial is stored), the report is
//    written from what is finished, and the command exits with 130.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/sweep/design/sweep_design.h"
#include "renderer/sweep/design/sweep_spec.h"

namespace ofl {

struct SweepRunOptions {
  std::filesystem::path out_dir = "sweep-out";
  int shard = 0, shards = 1;   // --shard i/N
  bool report_only = false;    // write the report from stored points, compute nothing
  bool dry_run = false;        // list the design and what is done, compute nothing
  bool render_progress = false;
  bool plot_files = false;      // also write the metric plots as SVG + PNG files under plots/
};

struct SweepRunSummary {
  int design_points = 0;     // in the whole design
  int shard_points = 0;      // in this shard
  int already_done = 0;      // of the shard's points, stored before this run
  int computed = 0;          // stored by this run (all ranks)
  int finished = 0;          // of the whole design, stored after this run
  int ranks = 1;
  bool interrupted = false;
  std::filesystem::path out_dir, csv, json, html;
  nlohmann::json to_json() const;
};

constexpr int kCheckAllPointsUpTo = 64;
constexpr size_t kDryRunListAll = 200, kDryRunListFirst = 20;
constexpr int kPointsTimed = 3;

// Which design points are loaded before anything is rendered (indices, ascending).
std::vector<int> points_checked_up_front(const SweepSpec& spec, const std::vector<DesignPoint>& design);

// Points of shard `shard` of `shards`: design indices i with i % shards == shard.
std::vector<int> shard_indices(int points, int shard, int shards);
// "i/N" -> (i, N) with 0 <= i < N; false when malformed.
bool parse_shard(const std::string& s, int* shard, int* shards);

// Throws InputError for bad input and Interrupted (after saving) on SIGINT.
SweepRunSummary run_sweep(const SweepSpec& spec, const SweepRunOptions& options);

}  // namespace ofl
