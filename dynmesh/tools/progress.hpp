// dynmesh/tools/progress.hpp — progress lines on stderr for long runs.
//
// Purpose: two kinds of line, both silent for the first second (progress_delay()), so that
// short runs print nothing:
//   * Progress: `[dynmesh] 1234/10000 updates`, for loops that can count their steps (edits,
//     updates). tick() refreshes it at most five times a second; finish() (or the destructor)
//     ends the line with a newline if anything was printed.
//   * Phase: `[dynmesh] building the quadtree of 2000000 points: 12 s`, for one long library
//     call that cannot report its own progress (a from-scratch build, the --check rebuild).
//     A background thread refreshes the elapsed time once a second (on a terminal); the destructor stops and
//     joins it, then ends the line: `...: done in 12.4 s` (or `...: stopped after 12.4 s` when
//     unwinding from an error).
// Both go to stderr; stdout is never touched. On a terminal each report rewrites the line in
// place with '\r'. Anywhere else (a log file, a pipe) each report is a line of its own, at
// most one every kLogInterval (10 s) per line, and no '\r' is written, so a log stays
// readable line by line.
// DYNMESH_PROGRESS_DELAY_MS (milliseconds, default 1000) overrides the one-second delay; the
// command-line tests set it to 0 to see the lines on small inputs.
// Invariants: nothing is printed before the delay has elapsed since construction. A Phase
// that lasts at least the delay always ends with its final line (printed by the destructor
// even if the thread never got to run), and its thread has ended when the destructor returns.
// Complexity: Progress::tick() is one clock read and a comparison, O(1); a Phase costs one
// thread that sleeps on a condition variable and wakes once a second.
// Paper: none.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

#include <unistd.h>

namespace dynmesh::tool {

/// How long a run stays silent before its progress line appears: one second, or
/// DYNMESH_PROGRESS_DELAY_MS milliseconds when that is set to a whole number (tests).
inline std::chrono::milliseconds progress_delay() {
  static const std::chrono::milliseconds delay = [] {
    const char* text = std::getenv("DYNMESH_PROGRESS_DELAY_MS");
    if (text == nullptr || *text == '\0') return std::chrono::milliseconds(1000);
    char* end = nullptr;
    const long long ms = std::strtoll(text, &end, 10);
    if (*end != '\0' || ms < 0) return std::chrono::milliseconds(1000);
    return std::chrono::milliseconds(ms);
  }();
  return delay;
}

/// Is stderr a terminal (reports rewrite one line) rather than a file or a pipe (reports are
/// lines of their own, at most one per kLogInterval)? Asked once.
inline bool progress_on_terminal() {
  static const bool terminal = ::isatty(STDERR_FILENO) == 1;
  return terminal;
}

/// The least time between two reports of one progress line when stderr is not a terminal.
inline constexpr std::chrono::seconds kLogInterval{10};

class Progress {
 public:
  Progress(std::string what, std::size_t total)
      : what_(std::move(what)), total_(total), start_(Clock::now()), last_(start_) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  // Unwinding from an error: end the line but do not claim the run completed.
  ~Progress() {
    if (std::uncaught_exceptions() > exceptions_) abandon();
    else finish();
  }

  void tick(std::size_t done) {
    const auto now = Clock::now();
    if (now - start_ < delay_) return;
    if (printed_ && now - last_ < (terminal_ ? Clock::duration(std::chrono::milliseconds(200)) : kLogInterval))
      return;
    last_ = now;
    printed_ = true;
    std::fprintf(stderr, terminal_ ? "\r[dynmesh] %zu/%zu %s" : "[dynmesh] %zu/%zu %s\n", done, total_, what_.c_str());
    std::fflush(stderr);
  }

  /// Prints the final count and a newline, once, if the line was shown at all.
  void finish() {
    if (!printed_) return;
    std::fprintf(stderr, terminal_ ? "\r[dynmesh] %zu/%zu %s\n" : "[dynmesh] %zu/%zu %s\n", total_, total_,
                 what_.c_str());
    std::fflush(stderr);
    printed_ = false;
  }

  /// Ends the line without claiming completion (an error is about to be reported).
  void abandon() {
    if (!printed_) return;
    if (terminal_) std::fputc('\n', stderr);  // elsewhere every report ended its line
    printed_ = false;
  }

 private:
  using Clock = std::chrono::steady_clock;
  std::string what_;
  std::size_t total_;
  Clock::time_point start_, last_;
  std::chrono::milliseconds delay_ = progress_delay();
  bool terminal_ = progress_on_terminal();
  bool printed_ = false;
  int exceptions_ = std::uncaught_exceptions();
};

/// The elapsed time of one long call, shown while it runs: construct before the call, let it
/// go out of scope after. `what` names the phase ("building the quadtree of 2000000 points").
class Phase {
 public:
  explicit Phase(std::string what) : what_(std::move(what)), start_(Clock::now()) {
    try {
      thread_ = std::thread([this] { run(); });
    } catch (const std::system_error&) {
      // No thread (a tight ulimit -v, say): the phase runs without a live line; the
      // destructor still prints the final one.
    }
  }
  Phase(const Phase&) = delete;
  Phase& operator=(const Phase&) = delete;

  ~Phase() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_one();
    if (thread_.joinable()) thread_.join();
    // After the join only this thread prints: the final line, if the phase lasted the delay.
    const Clock::duration elapsed = Clock::now() - start_;
    if (elapsed < delay_) return;
    const bool failed = std::uncaught_exceptions() > exceptions_;
    std::fprintf(stderr, "%s[dynmesh] %s: %s %.1f s\n", terminal_ ? "\r" : "", what_.c_str(),
                 failed ? "stopped after" : "done in", std::chrono::duration<double>(elapsed).count());
    std::fflush(stderr);
  }

 private:
  using Clock = std::chrono::steady_clock;

  // The thread: wait out the delay, then print the whole seconds elapsed once a second, until
  // the destructor says stop. It allocates nothing (fprintf to unbuffered stderr).
  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    Clock::time_point next = start_ + delay_;
    while (!wake_.wait_until(lock, next, [this] { return stopping_; })) {
      const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(Clock::now() - start_).count();
      std::fprintf(stderr, terminal_ ? "\r[dynmesh] %s: %lld s" : "[dynmesh] %s: %lld s\n", what_.c_str(),
                   static_cast<long long>(seconds));
      std::fflush(stderr);
      next += terminal_ ? Clock::duration(std::chrono::seconds(1)) : kLogInterval;
    }
  }

  std::string what_;
  Clock::time_point start_;
  std::chrono::milliseconds delay_ = progress_delay();
  bool terminal_ = progress_on_terminal();
  int exceptions_ = std::uncaught_exceptions();
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;  // guarded by mutex_
  std::thread thread_;     // last: started once every other member is ready
};

}  // namespace dynmesh::tool
