#include "renderer/core/process/progress.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>

#include "renderer/core/errors/error.h"

namespace ofl {
namespace {
std::atomic<bool> g_interrupt{false};
void on_signal(int sig) {
  if (g_interrupt.exchange(true)) std::_Exit(128 + sig);
  const char msg[] = "\ninterrupt: finishing the work in progress and saving (press Ctrl-C again to abort)\n";
  ssize_t r = write(2, msg, sizeof msg - 1);
  (void)r;
}
}  // namespace

bool ProgressBar::enabled() { return !std::getenv("OFL_NO_PROGRESS"); }
bool ProgressBar::terminal() { return isatty(2); }

namespace {
std::chrono::milliseconds log_interval() {
  double s = 5.0;
  if (const char* e = std::getenv("OFL_PROGRESS_SECONDS")) {
    char* end = nullptr;
    double v = std::strtod(e, &end);
    if (end != e && v >= 0.05 && v <= 3600) s = v;
  }
  return std::chrono::milliseconds(static_cast<int64_t>(s * 1000));
}
}  // namespace

ProgressBar::ProgressBar(std::string label, int64_t total)
    : label_(std::move(label)), total_(total > 0 ? total : 1), start_(std::chrono::steady_clock::now()),
      last_draw_(start_), active_(enabled()), tty_(terminal()),
      interval_(tty_ ? std::chrono::milliseconds(200) : log_interval()) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::advance(int64_t n) {
  int64_t d = done_.fetch_add(n) + n;
  if (!active_) return;
  auto now = std::chrono::steady_clock::now();
  std::unique_lock lock(mu_, std::try_to_lock);
  if (!lock.owns_lock() || now - last_draw_ < interval_) return;
  last_draw_ = now;
  draw(d);
}

void ProgressBar::draw(int64_t d) {
  double f = std::min(1.0, double(d) / total_);
  double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  double eta = f > 0 ? el * (1 - f) / f : 0;
  if (!tty_) {  // a log: one complete line each time
    std::fprintf(stderr, "%s: %5.1f %% (%lld of %lld), %.0f s elapsed, %.0f s left\n", label_.c_str(), 100 * f,
                 static_cast<long long>(d), static_cast<long long>(total_), el, eta);
    std::fflush(stderr);
    return;
  }
  int w = 30, k = static_cast<int>(f * w);
  std::string bar(k, '#');
  bar += std::string(w - k, '.');
  std::fprintf(stderr, "\r%s [%s] %5.1f%%  %.0fs elapsed, %.0fs left ", label_.c_str(), bar.c_str(), 100 * f, el, eta);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (!active_ || finished_) return;
  finished_ = true;
  draw(done_.load());
  if (tty_) std::fprintf(stderr, "\n");
}

void install_interrupt_handler() {
  static bool done = false;
  if (done) return;
  done = true;
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}
bool interrupt_requested() { return g_interrupt.load(std::memory_order_relaxed); }
void throw_if_interrupted(const char* doing) {
  if (interrupt_requested()) throw Interrupted(std::string("while ") + doing);
}

}  // namespace ofl
