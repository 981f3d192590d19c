#include "tools/chorus/progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace chorus::cli {
namespace {

constexpr int kBarWidth = 30;

std::string bar(double fraction, int width) {
  const int filled = std::clamp(int(fraction * width), 0, width);
  return std::string(size_t(filled), '#') + std::string(size_t(width - filled), '-');
}

std::string runsProgressText(const RunsProgress& p, double elapsedSeconds) {
  const double fraction = p.total > 0 ? double(p.done) / double(p.total) : 1.0;
  char text[256];
  std::snprintf(text, sizeof text, "denoising [%s] %2zu/%zu member runs, %.1f s",
                bar(fraction, kBarWidth).c_str(), p.done, p.total, elapsedSeconds);
  std::string line = text;
  if (!p.finished.empty()) {
    std::snprintf(text, sizeof text, " (%s took %.1f s)", p.finished.c_str(), p.seconds);
    line += text;
  }
  return line;
}

}  // namespace

bool TerminalLine::stderrIsTerminal() {
  return ::isatty(STDERR_FILENO) == 1;
}

void TerminalLine::draw(const std::string& text, bool force) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && !force && now - lastDraw_ < std::chrono::milliseconds(100)) return;
  lastDraw_ = now;
  drawn_ = true;
  std::fprintf(stderr, "\r%s ", text.c_str());
  std::fflush(stderr);
}

void TerminalLine::finish() {
  if (drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

void ProgressBar::update(const render::RenderProgress& p) {
  if (!line_.enabled()) return;
  const double fraction = p.fraction();
  const double rate = p.elapsedSeconds > 0 ? double(p.samplesDone) / p.elapsedSeconds : 0;
  const double eta = rate > 0 ? double(p.samplesTotal - p.samplesDone) / rate : 0;
  char text[160];
  std::snprintf(text, sizeof text, "[%s] %5.1f%%  %6.2f M samples/s  ETA %5.1f s",
                bar(fraction, kBarWidth).c_str(), 100.0 * fraction, rate / 1e6, eta);
  line_.draw(text, p.samplesDone >= p.samplesTotal);
}

RunsProgressCallback RunsProgressLine::callback() {
  if (!line_.enabled()) return {};
  return [this](const RunsProgress& p) {
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start_;
    line_.draw(runsProgressText(p, elapsed.count()), p.done == p.total);
  };
}

}  // namespace chorus::cli
