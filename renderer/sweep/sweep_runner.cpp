#include "renderer/sweep/sweep_runner.h"

#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <thread>

#include "renderer/core/errors/error.h"
#include "renderer/core/process/progress.h"
#include "renderer/sweep/design/rig_generators.h"
#include "renderer/sweep/design/sweep_design.h"
#include "renderer/sweep/sweep_mpi.h"
#include "renderer/sweep/store/render_cache.h"
#include "renderer/sweep/sweep_point.h"
#include "renderer/sweep/sweep_report.h"
#include "renderer/sweep/store/sweep_lock.h"
#include "renderer/sweep/store/sweep_store.h"

namespace ofl {

std::vector<int> shard_indices(int points, int shard, int shards) {
  std::vector<int> v;
  for (int i = 0; i < points; ++i)
    if (i % shards == shard) v.push_back(i);
  return v;
}

bool parse_shard(const std::string& s, int* shard, int* shards) {
  int i = 0, n = 0;
  char tail;
  if (std::sscanf(s.c_str(), "%d/%d%c", &i, &n, &tail) != 2) return false;
  if (n < 1 || i < 0 || i >= n) return false;
  *shard = i;
  *shards = n;
  return true;
}

nlohmann::json SweepRunSummary::to_json() const {
  return {{"design_points", design_points}, {"shard_points", shard_points}, {"already_done", already_done},
          {"computed", computed},           {"finished", finished},         {"missing", design_points - finished},
          {"ranks", ranks},                 {"interrupted", interrupted},   {"out_dir", out_dir.string()},
          {"csv", csv.string()},            {"json", json.string()},        {"html", html.string()}};
}

namespace {

void log_line(int rank, int ranks, const std::string& s) {
  if (ranks > 1) std::fprintf(stderr, "sweep[rank %d] %s\n", rank, s.c_str());
  else std::fprintf(stderr, "sweep: %s\n", s.c_str());
  std::fflush(stderr);
}

std::string done_line(const nlohmann::ordered_json& r) {
  char b[256];
  const auto& rd = r["render"];
  std::snprintf(b, sizeof b, "point %d done in %.1f s (%d spp, relative noise %.3f%s)", r["index"].get<int>(),
                r["seconds"].get<double>(), rd["spp"].get<int>(), rd["relative_noise"].get<double>(),
                r.value("render_cached", false) ? ", render from renders/" : "");
  return b;
}

struct Work {
  const SweepSpec& spec;
  const SweepRunOptions& opt;
  std::vector<DesignPoint> design;
  std::vector<std::string> keys;
};

// Rank 0: store a result received from a worker (after checking it is a point of this design).
void store_received(const std::string& payload, const Work& w, const PointStore& store, int* computed) {
  nlohmann::ordered_json r = nlohmann::ordered_json::parse(payload);
  std::string key = r.value("key", std::string());
  int idx = r.value("index", -1);
  if (idx < 0 || idx >= int(w.keys.size()) || w.keys[idx] != key)
    throw std::runtime_error("a rank sent a result that is not a point of this design (key " + key + ")");
  store.save(key, r);
  ++*computed;
}

// Every point's key (fast: the files' text is hashed once, not per point), checking for SIGINT.
std::vector<std::string> design_keys(const SweepSpec& spec, const std::vector<DesignPoint>& design) {
  PointKeys keys(spec);
  std::vector<std::string> out;
  out.reserve(design.size());
  for (const auto& p : design) {
    if ((p.index & 1023) == 0) throw_if_interrupted("computing the design points' keys; nothing was computed");
    out.push_back(keys.key(p));
  }
  return out;
}

// Loads the points whose scene and camera are checked before anything is rendered (sweep_runner.h).
void check_points_up_front(const SweepSpec& spec, const std::vector<DesignPoint>& design, int rank) {
  std::vector<int> which = points_checked_up_front(spec, design);
  if (rank == 0 && which.size() < design.size())
    log_line(0, 1, "checking " + std::to_string(which.size()) + " of the " + std::to_string(design.size()) +
                       " points up front (every level of every parameter; the rest load when they run)");
  for (int i : which) {
    throw_if_interrupted("checking the design points' scenes and cameras; nothing was computed");
    load_point(spec, design[size_t(i)]);
  }
}

// The dry run's answer: counts, and the points (all of a small design, the first ones of a large one).
void print_dry_run(const Work& w, const PointStore& store, const std::vector<int>& shard, int already_done) {
  const size_t n = w.design.size(), listed = n <= kDryRunListAll ? n : kDryRunListFirst;
  for (size_t i = 0; i < listed; ++i)
    std::printf("%4zu  %s  %-8s %s\n", i, w.keys[i].c_str(), store.has(w.keys[i]) ? "done" : "missing",
                point_label(w.spec, w.design[i]).c_str());
  if (listed < n) std::printf("... %zu more points not listed\n", n - listed);
  std::printf("%zu points in the design, %zu in this shard: %d done, %zu to compute\n", n, shard.size(), already_done,
              shard.size() - size_t(already_done));
}

// "a point takes about 4.2 s (mean of the first 3); the 997 left need about 1.2 h on this process".
std::string estimate_line(double seconds, int points_timed, size_t left) {
  const double mean = seconds / std::max(1, points_timed), total = mean * double(left);
  char b[200];
  const double shown = total >= 7200 ? total / 3600 : total >= 120 ? total / 60 : total;
  const char* unit = total >= 7200 ? "h" : total >= 120 ? "min" : "s";
  std::snprintf(b, sizeof b, "a point takes about %.3g s (mean of the first %d); the %zu left need about %.3g %s on this process",
                mean, points_timed, left, shown, unit);
  return b;
}

}  // namespace

std::vector<int> points_checked_up_front(const SweepSpec& spec, const std::vector<DesignPoint>& design) {
  std::vector<int> out;
  if (design.size() <= size_t(kCheckAllPointsUpTo)) {
    for (size_t i = 0; i < design.size(); ++i) out.push_back(int(i));
    return out;
  }
  std::set<int> picked;
  for (size_t pi = 0; pi < spec.parameters.size(); ++pi) {
    std::map<int, int> first_of_level;  // listed levels: the first point with each
    int lo = -1, hi = -1;               // continuous ranges: the points with the extreme values
    for (size_t i = 0; i < design.size(); ++i) {
      const DesignPoint& p = design[i];
      if (p.level[pi] >= 0) {
        first_of_level.emplace(p.level[pi], int(i));
        continue;
      }
      double v = p.values[pi].get<double>();
      if (lo < 0 || v < design[size_t(lo)].values[pi].get<double>()) lo = int(i);
      if (hi < 0 || v > design[size_t(hi)].values[pi].get<double>()) hi = int(i);
    }
    for (auto& [level, i] : first_of_level) picked.insert(i);
    if (lo >= 0) picked.insert(lo);
    if (hi >= 0) picked.insert(hi);
  }
  return std::vector<int>(picked.begin(), picked.end());
}

namespace {

void write_manifest(const Work& w) {
  nlohmann::ordered_json manifest;
  manifest["spec"] = w.spec.to_json();
  manifest["points"] = nlohmann::json::array();
  for (size_t i = 0; i < w.design.size(); ++i)
    manifest["points"].push_back(
        {{"index", i}, {"key", w.keys[i]}, {"label", point_label(w.spec, w.design[i])}, {"values", w.design[i].values}});
  write_file_atomic(w.opt.out_dir / "sweep.json", manifest.dump(1) + "\n");
}

// Rank 0's bookkeeping before computing: the folder lock, the manifest, what is done and what is
// left; prints the dry run's answer. Returns the points left to compute, as JSON text for the ranks.
std::string plan_work(const Work& w, const std::vector<int>& shard, std::optional<PointStore>& store,
                      std::optional<FolderLock>& folder_lock, bool mpi, SweepRunSummary& sum) {
  const SweepRunOptions& opt = w.opt;
  store.emplace(opt.out_dir, !opt.dry_run);
  if (!opt.dry_run && !opt.report_only) {
    folder_lock.emplace(opt.out_dir, ".sweep.lock", mpi ? FolderLock::Mode::kExclusive : FolderLock::Mode::kShared, false,
                        mpi ? "an MPI sweep needs the folder to itself: wait for it to end or choose another -o"
                            : "it is an MPI sweep, which needs the folder to itself: wait for it to end or choose another -o");
    store->remove_stale_temporaries();
    write_manifest(w);
  }
  nlohmann::json todo = nlohmann::json::array();
  for (int i : shard) {
    const std::string& key = w.keys[size_t(i)];
    if (store->has(key)) {
      ++sum.already_done;
      continue;
    }
    todo.push_back(i);
    std::error_code ec;  // a file under the point's name that is not its result: said, then replaced
    if (std::filesystem::exists(store->file_for(key), ec))
      std::fprintf(stderr, "warning: %s: not a complete result of this point; it is computed again\n", store->file_for(key).c_str());
  }
  if (opt.dry_run) print_dry_run(w, *store, shard, sum.already_done);
  if (opt.dry_run || opt.report_only) todo = nlohmann::json::array();
  return todo.dump();
}

// The report, from the points stored when the report lock is taken: when several sweeps share the
// folder, the last one to get here sees every point.
void write_report(const Work& w, const PointStore& store, SweepRunSummary& sum) {
  if (w.opt.dry_run) return;
  FolderLock lock(w.opt.out_dir, ".report.lock", FolderLock::Mode::kExclusive, true, "");
  std::vector<std::optional<nlohmann::ordered_json>> results;
  for (auto& key : w.keys) {
    results.push_back(store.load(key));
    if (!results.back()) continue;
    if (size_t(++sum.finished) > kReportPointsShown) drop_report_only_members(*results.back());
  }
  ReportOptions ro;
  ro.plot_files = w.opt.plot_files;
  ReportFiles files = write_sweep_report(w.spec, w.design, results, w.opt.out_dir, ro);
  sum.csv = files.csv;
  sum.json = files.json;
  sum.html = files.html;
}

// Computes this rank's points. A single process claims each point first (sweep_lock.h) and skips
// points another sweep in the folder is computing or has finished meanwhile.
struct PointLoop {
  const Work& w;
  MpiSession& mpi;
  const std::optional<PointStore>& store;
  SweepRunSummary& sum;
  std::function<void()> poll;  // rank 0: handle the other ranks' messages
  int sent = 0, claimed_elsewhere = 0;
  std::string elsewhere;  // who held them
  double timed_seconds = 0;
  int timed = 0;

  void run(const std::vector<int>& mine, PointRunContext& ctx) {
    const int rank = mpi.rank(), ranks = mpi.size();
    for (size_t k = 0; k < mine.size(); ++k) {
      if (interrupt_requested()) {
        sum.interrupted = true;
        break;
      }
      if (rank == 0) poll();
      const DesignPoint& p = w.design[size_t(mine[k])];
      std::optional<PointClaim> claim;
      if (ranks == 1) {
        claim.emplace(store->dir(), w.keys[size_t(p.index)]);
        if (!claim->held()) {
          ++claimed_elsewhere;
          elsewhere = claim->holder();
          continue;
        }
        if (store->has(w.keys[size_t(p.index)])) continue;  // finished by another sweep meanwhile
      }
      char head[96];
      std::snprintf(head, sizeof head, "[%zu/%zu] point %d: ", k + 1, mine.size(), p.index);
      log_line(rank, ranks, head + point_label(w.spec, p));
      auto t0 = std::chrono::steady_clock::now();
      PointOutcome o;
      try {
        o = evaluate_point(w.spec, p, ctx);
      } catch (const Interrupted&) {  // while loading the point (a layered tissue's table, say)
        o.interrupted = true;
      }
      if (o.interrupted) {
        sum.interrupted = true;
        log_line(rank, ranks, "interrupted: point " + std::to_string(p.index) + " abandoned (nothing stored for it)");
        break;
      }
      log_line(rank, ranks, done_line(o.result));
      if (rank == 0) {
        store->save(w.keys[size_t(p.index)], o.result);
        ++sum.computed;
      } else {
        mpi.send(MpiSession::kResult, o.result.dump());
        ++sent;
      }
      // Sizing: how long a point takes, from the first few, and what that means for the rest.
      if (timed < kPointsTimed) {
        timed_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        ++timed;
        if (k + 1 < mine.size() && (timed == 1 || timed == kPointsTimed))
          log_line(rank, ranks, estimate_line(timed_seconds, timed, mine.size() - k - 1));
      }
    }
  }
};

}  // namespace

SweepRunSummary run_sweep(const SweepSpec& spec, const SweepRunOptions& opt) {
  MpiSession mpi;
  SweepRunSummary sum;
  sum.ranks = mpi.size();
  sum.out_dir = opt.out_dir;
  const int rank = mpi.rank(), ranks = mpi.size();
  try {
    Work w{spec, opt, make_design(spec), {}};
    sum.design_points = int(w.design.size());
    w.keys = design_keys(spec, w.design);
    // A pointer that does not fit the scene, or a value the scene or camera loader rejects, is
    // reported (naming the sweep file's parameter) before anything is rendered: every point of a
    // small design, every level of every parameter of a large one (points_checked_up_front).
    if (!opt.report_only) check_points_up_front(spec, w.design, rank);
    std::vector<int> shard = shard_indices(sum.design_points, opt.shard, opt.shards);
    sum.shard_points = int(shard.size());

    std::optional<PointStore> store;
    std::optional<FolderLock> folder_lock;
    std::string todo_text;
    if (rank == 0) todo_text = plan_work(w, shard, store, folder_lock, mpi.active(), sum);
    mpi.broadcast(todo_text);
    nlohmann::json todo = nlohmann::json::parse(todo_text);
    std::vector<int> mine;
    for (size_t k = 0; k < todo.size(); ++k)
      if (int(k % size_t(ranks)) == rank) mine.push_back(todo[k].get<int>());
    if (rank == 0 && !opt.dry_run && !opt.report_only) {
      char b[200];
      std::snprintf(b, sizeof b, "%d points in the design, %d in this shard, %d already done, %zu to compute on %d rank(s)",
                    sum.design_points, sum.shard_points, sum.already_done, todo.size(), ranks);
      log_line(rank, 1, b);
    }

    PointRunContext ctx;
    // Every rank keeps renders in <out>/renders (shared or node-local: either way a key names one
    // render, and concurrent writers of a key write the same bytes).
    std::optional<RenderCache> cache;
    if (spec.render.cache && !mine.empty()) cache.emplace(opt.out_dir);
    ctx.render_cache = cache ? &*cache : nullptr;
    ctx.rank = rank;
    ctx.progress = opt.render_progress && ranks == 1;
    int done_ranks = 0;
    std::string error;
    MpiSession::Message msg;
    // Rank 0 handles the other ranks' messages between its own points and at the end.
    auto handle = [&](const MpiSession::Message& m) {
      if (m.tag == MpiSession::kResult) store_received(m.payload, w, *store, &sum.computed);
      else if (m.tag == MpiSession::kDone) ++done_ranks;
      else if (m.tag == MpiSession::kError) {
        error += (error.empty() ? "" : "; ") + ("rank " + std::to_string(m.source) + ": " + m.payload);
        ++done_ranks;
      }
    };
    PointLoop loop{w, mpi, store, sum, [&] {
                     while (mpi.receive(&msg, false)) handle(msg);
                   }};
    loop.run(mine, ctx);
    if (rank != 0) {
      mpi.send(MpiSession::kDone, std::to_string(loop.sent));
      mpi.wait_sends();
      return sum;
    }
    while (done_ranks < ranks - 1) {
      if (mpi.receive(&msg, false)) handle(msg);
      else std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    if (interrupt_requested()) sum.interrupted = true;
    if (loop.claimed_elsewhere > 0)
      log_line(0, 1, std::to_string(loop.claimed_elsewhere) + " point(s) were being computed by another sweep in this folder (" +
                         loop.elsewhere + "); the last sweep to finish writes the report with them");
    write_report(w, *store, sum);
    if (!error.empty()) throw std::runtime_error(error);
    return sum;
  } catch (const std::exception& e) {
    if (!mpi.active()) throw;
    // Under MPI rank 0 failing would leave the others waiting for it: report and end every rank.
    const auto* ie = dynamic_cast<const InputError*>(&e);
    if (rank != 0) {
      // Tell rank 0, which stops waiting for this rank and still writes what the others finish.
      mpi.send(MpiSession::kError, ie ? ie->describe() : std::string(e.what()));
      mpi.wait_sends();
      throw;
    }
    std::fprintf(stderr, "%s (rank %d): %s\n", ie ? "error" : "internal error", rank,
                 ie ? ie->describe().c_str() : e.what());
    std::fflush(stderr);
    mpi.abort(ie ? kExitBadInput : kExitInternal);
  }
}

}  // namespace ofl
