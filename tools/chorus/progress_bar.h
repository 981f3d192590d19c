#pragma once
// Progress on stderr, redrawn in place when stderr is a terminal (at most 10 times a second);
// nothing while running otherwise (the command prints one summary line at the end instead):
// the render's bar with percentage, samples/s and ETA, and the denoisers' count of finished
// member runs (a default job's members run for several times the render's time).
#include <chrono>
#include <cstdint>
#include <string>

#include "denoise/pipeline/ensemble.h"
#include "renderer/render.h"

namespace chorus::cli {

// One line of stderr that a progress display redraws.
class TerminalLine {
 public:
  // enabled = false silences it (--quiet, or stderr is not a terminal).
  explicit TerminalLine(bool enabled) : enabled_(enabled) {}

  bool enabled() const { return enabled_; }
  // Redraws the line with `text`, unless it was drawn less than 0.1 s ago and !force.
  void draw(const std::string& text, bool force);
  // Ends the line (if one was drawn).
  void finish();

  static bool stderrIsTerminal();

 private:
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point lastDraw_{};
};

class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : line_(enabled) {}
  void update(const render::RenderProgress& p);
  void finish() { line_.finish(); }

 private:
  TerminalLine line_;
};

// "denoising [####------]  5/12 member runs, 21.4 s (nfor/without-q1 took 8.3 s)"
class RunsProgressLine {
 public:
  explicit RunsProgressLine(bool enabled) : line_(enabled) {}
  // For runBaseDenoisers / runMembersAlone; empty when disabled.
  RunsProgressCallback callback();
  void finish() { line_.finish(); }

 private:
  TerminalLine line_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace chorus::cli
