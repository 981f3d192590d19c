#pragma once
// Render progress on stderr: a bar with percentage, samples/s and ETA redrawn in place when
// stderr is a terminal (at most 10 times a second); nothing while running otherwise (the
// command prints one summary line at the end instead).
#include <chrono>
#include <cstdint>

#include "renderer/render.h"

namespace chorus::cli {

class ProgressBar {
 public:
  // enabled = false silences it (--quiet, or stderr is not a terminal).
  explicit ProgressBar(bool enabled) : enabled_(enabled) {}

  void update(const render::RenderProgress& p);
  // Ends the bar's line (if one was drawn).
  void finish();

  static bool stderrIsTerminal();

 private:
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point lastDraw_{};
};

}  // namespace chorus::cli
