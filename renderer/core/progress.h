// Progress bar on stderr for long work (quiet when stderr is not a terminal), and SIGINT
// handling so that long work can stop cleanly and keep what it finished.
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
  static bool enabled();        // stderr is a terminal and OFL_NO_PROGRESS is unset

 private:
  void draw(int64_t done);
  std::string label_;
  int64_t total_;
  std::atomic<int64_t> done_{0};
  std::mutex mu_;
  std::chrono::steady_clock::time_point start_, last_draw_;
  bool active_, finished_ = false;
};

// Installs a SIGINT/SIGTERM handler (idempotent). The first signal sets the flag that
// interrupt_requested() reports; a second one ends the process at once.
void install_interrupt_handler();
bool interrupt_requested();
void clear_interrupt();  // for tests

}  // namespace ofl
