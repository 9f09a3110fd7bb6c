#include "renderer/sweep/sweep_runner.h"

#include <chrono>
#include <cstdio>
#include <optional>
#include <thread>

#include "renderer/core/error.h"
#include "renderer/core/progress.h"
#include "renderer/sweep/rig_generators.h"
#include "renderer/sweep/sweep_design.h"
#include "renderer/sweep/sweep_mpi.h"
#include "renderer/sweep/render_cache.h"
#include "renderer/sweep/sweep_point.h"
#include "renderer/sweep/sweep_report.h"
#include "renderer/sweep/sweep_store.h"

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
    // Every point's documents are built and loaded once up front, so a pointer that does not fit
    // the scene, or a value the scene or camera loader rejects, is reported (naming the sweep
    // file's parameter) before anything is rendered.
    for (auto& p : w.design) {
      load_point(spec, p);
      w.keys.push_back(point_key(spec, p));
    }
    std::vector<int> shard = shard_indices(sum.design_points, opt.shard, opt.shards);
    sum.shard_points = int(shard.size());

    std::optional<PointStore> store;
    std::string todo_text;
    if (rank == 0) {
      store.emplace(opt.out_dir, !opt.dry_run);
      if (!opt.dry_run) store->remove_stale_temporaries();
      nlohmann::ordered_json manifest;
      manifest["spec"] = spec.to_json();
      manifest["points"] = nlohmann::json::array();
      for (size_t i = 0; i < w.design.size(); ++i)
        manifest["points"].push_back(
            {{"index", i}, {"key", w.keys[i]}, {"label", point_label(spec, w.design[i])}, {"values", w.design[i].values}});
      if (!opt.dry_run && !opt.report_only) write_file_atomic(opt.out_dir / "sweep.json", manifest.dump(1) + "\n");
      nlohmann::json todo = nlohmann::json::array();
      for (int i : shard) {
        if (store->has(w.keys[i])) ++sum.already_done;
        else todo.push_back(i);
      }
      if (opt.dry_run) {
        for (size_t i = 0; i < w.design.size(); ++i)
          std::printf("%4zu  %s  %-8s %s\n", i, w.keys[i].c_str(), store->has(w.keys[i]) ? "done" : "missing",
                      point_label(spec, w.design[i]).c_str());
      }
      if (opt.dry_run || opt.report_only) todo = nlohmann::json::array();
      todo_text = todo.dump();
    }
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
    int sent = 0, done_ranks = 0;
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
    for (size_t k = 0; k < mine.size(); ++k) {
      if (interrupt_requested()) {
        sum.interrupted = true;
        break;
      }
      if (rank == 0)
        while (mpi.receive(&msg, false)) handle(msg);
      const DesignPoint& p = w.design[mine[k]];
      char head[96];
      std::snprintf(head, sizeof head, "[%zu/%zu] point %d: ", k + 1, mine.size(), p.index);
      log_line(rank, ranks, head + point_label(spec, p));
      PointOutcome o = evaluate_point(spec, p, ctx);
      if (o.interrupted) {
        sum.interrupted = true;
        log_line(rank, ranks, "interrupted: point " + std::to_string(p.index) + " abandoned (nothing stored for it)");
        break;
      }
      log_line(rank, ranks, done_line(o.result));
      if (rank == 0) {
        store->save(w.keys[p.index], o.result);
        ++sum.computed;
      } else {
        mpi.send(MpiSession::kResult, o.result.dump());
        ++sent;
      }
    }
    if (rank != 0) {
      mpi.send(MpiSession::kDone, std::to_string(sent));
      mpi.wait_sends();
      return sum;
    }
    while (done_ranks < ranks - 1) {
      if (mpi.receive(&msg, false)) handle(msg);
      else std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    if (interrupt_requested()) sum.interrupted = true;

    std::vector<std::optional<nlohmann::ordered_json>> results;
    for (auto& key : w.keys) {
      results.push_back(store->load(key));
      if (results.back()) ++sum.finished;
    }
    if (!opt.dry_run) {
      ReportOptions ro;
      ro.plot_files = opt.plot_files;
      ReportFiles files = write_sweep_report(spec, w.design, results, opt.out_dir, ro);
      sum.csv = files.csv;
      sum.json = files.json;
      sum.html = files.html;
    }
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
