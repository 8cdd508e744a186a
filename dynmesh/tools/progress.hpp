// dynmesh/tools/progress.hpp — a progress line on stderr for long runs.
//
// Purpose: `[dynmesh] 1234/10000 updates`, rewritten in place with '\r'. Silent for the
// first second (short runs print nothing), then refreshed at most five times a second;
// finish() (or the destructor) ends the line with a newline if anything was printed. It goes to stderr whether
// or not stderr is a terminal (a log file gets the '\r'-separated updates).
// Invariants: nothing is printed before one second has elapsed since construction.
// Complexity: tick() is one clock read and a comparison, O(1).
// Paper: none.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <string>
#include <utility>

namespace dynmesh::tool {

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
    if (now - start_ < std::chrono::seconds(1)) return;
    if (printed_ && now - last_ < std::chrono::milliseconds(200)) return;
    last_ = now;
    printed_ = true;
    std::fprintf(stderr, "\r[dynmesh] %zu/%zu %s", done, total_, what_.c_str());
    std::fflush(stderr);
  }

  /// Prints the final count and a newline, once, if the line was shown at all.
  void finish() {
    if (!printed_) return;
    std::fprintf(stderr, "\r[dynmesh] %zu/%zu %s\n", total_, total_, what_.c_str());
    std::fflush(stderr);
    printed_ = false;
  }

  /// Ends the line without claiming completion (an error is about to be reported).
  void abandon() {
    if (!printed_) return;
    std::fputc('\n', stderr);
    printed_ = false;
  }

 private:
  using Clock = std::chrono::steady_clock;
  std::string what_;
  std::size_t total_;
  Clock::time_point start_, last_;
  bool printed_ = false;
  int exceptions_ = std::uncaught_exceptions();
};

}  // namespace dynmesh::tool
