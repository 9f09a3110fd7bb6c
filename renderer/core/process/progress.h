// Progress of long work on stderr: a bar redrawn in place on a terminal, and a plain line every few
// seconds (OFL_PROGRESS_SECONDS, default 5) when stderr is a file or a pipe, so logs of batch jobs
// show it too; OFL_NO_PROGRESS silences both. And SIGINT handling so that long work can stop
// cleanly and keep what it finished.
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace ofl {

class ProgressBar {
 public:
  ProgressBar(std::string label, int64_t total);
  ~ProgressBar();
  void advance(int64_t n = 1);  // thread safe
  void finish();
  static bool enabled();        // OFL_NO_PROGRESS is unset
  static bool terminal();       // stderr is a terminal (bar) rather than a log (lines)

 private:
  void draw(int64_t done);
  std::string label_;
  int64_t total_;
  std::atomic<int64_t> done_{0};
  std::mutex mu_;
  std::chrono::steady_clock::time_point start_, last_draw_;
  bool active_, tty_, finished_ = false;
  std::chrono::milliseconds interval_;
};

// Installs a SIGINT/SIGTERM handler (idempotent). The first signal sets the flag that
// interrupt_requested() reports; a second one ends the process at once.
void install_interrupt_handler();
bool interrupt_requested();
// Throws Interrupted("while <doing>") (printed as "interrupted: while <doing>") once SIGINT/SIGTERM has arrived: the check that
// phases with nothing to save (loading, checking, tabulating) make between steps, so the first
// Ctrl-C takes effect within a step rather than after the whole phase.
void throw_if_interrupted(const char* doing);

}  // namespace ofl
