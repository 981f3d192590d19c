#include "tools/chorus/progress_bar.h"

#include <unistd.h>

#include <cstdio>
#include <string>

namespace chorus::cli {

bool ProgressBar::stderrIsTerminal() {
  return ::isatty(STDERR_FILENO) == 1;
}

void ProgressBar::update(const render::RenderProgress& p) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const bool done = p.samplesDone >= p.samplesTotal;
  if (drawn_ && !done && now - lastDraw_ < std::chrono::milliseconds(100)) return;
  lastDraw_ = now;
  drawn_ = true;

  constexpr int kWidth = 30;
  const double fraction = p.fraction();
  const int filled = int(fraction * kWidth);
  const std::string bar =
      std::string(size_t(filled), '#') + std::string(size_t(kWidth - filled), '-');
  const double rate = p.elapsedSeconds > 0 ? double(p.samplesDone) / p.elapsedSeconds : 0;
  const double eta = rate > 0 ? double(p.samplesTotal - p.samplesDone) / rate : 0;
  std::fprintf(stderr, "\r[%s] %5.1f%%  %6.2f M samples/s  ETA %5.1f s ", bar.c_str(),
               100.0 * fraction, rate / 1e6, eta);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace chorus::cli
