#pragma once
// How many worker threads a run may use, shared by the renderer, the denoisers and the tools:
// one range check for every --threads flag, and a process-wide TBB limit for the stages that
// run outside the renderer's own task arena (the denoisers, sweeps, benchmarks).
#include <tbb/global_control.h>

#include <optional>

namespace chorus {

// More threads than any machine chorus runs on has cores; TBB's arena crashes on values near
// INT_MAX, so a larger request is an error rather than a crash.
inline constexpr int kMaxThreads = 1024;

// Throws chorus::Error ("--threads must be 0 (all cores) … 1024, got N") outside 0 … kMaxThreads.
void checkThreadCount(int threads);

// While alive, TBB runs at most `threads` workers in this process (0: no limit, all cores).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);

 private:
  std::optional<tbb::global_control> control_;
};

}  // namespace chorus
