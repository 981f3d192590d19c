#pragma once
// Wall-clock seconds since construction (or the last restart), for stage timings in stats.json,
// sweep tables and benchmarks; and the process's CPU time, for the benchmarks.
#include <time.h>

#include <chrono>

namespace chorus {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  // The seconds so far; starts again from now.
  double restart() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// CPU seconds (user + system) of every thread of this process so far.
inline double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace chorus
