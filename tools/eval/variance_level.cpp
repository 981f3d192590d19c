// variance_level RENDER.exr REFERENCE.exr: how well a render's recorded colour variance states the
// noise its full buffer actually carries (docs/variance-calibration.md). Prints, weighted as
// relMSE weighs errors (1 / (reference² + 0.01)) and averaged over pixels and channels: the full
// buffer's squared error against the reference, the recorded variance of its mean, the
// estimate from the spread of the K sub-buffers' means (unbiased for independent sub-buffers),
// and the recorded variance calibrated to the halves (variance_calibration.h, radius 3).
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <string>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "denoise/base/variance_calibration.h"
#include "denoise/buffers/buffers_exr.h"
#include "denoise/metrics/metrics.h"
#include "tools/eval/tool_main.h"

namespace chorus {
namespace {

// A variance image averaged as relMSE averages squared errors: each value over (reference² + ε).
double relativeMean(const Image& variance, const Image& reference) {
  double sum = 0;
  for (size_t k = 0; k < variance.size(); ++k) {
    const double r = reference.data()[k];
    sum += variance.data()[k] / (r * r + kRelMseEpsilon);
  }
  return sum / double(variance.size());
}

// The variance of the mean of the K sub-buffers' means, from their spread (unbiased for
// independent sub-buffers).
Image subBufferSpread(const SampleBuffers& buffers) {
  const int K = buffers.splitCount();
  const Image& first = buffers.sub(0).color.mean;
  Image spread(first.width(), first.height(), first.channels());
  for (size_t e = 0; e < spread.size(); ++e) {
    double mean = 0, squares = 0;
    for (int k = 0; k < K; ++k) mean += buffers.sub(k).color.mean.data()[e];
    mean /= K;
    for (int k = 0; k < K; ++k) squares += std::pow(buffers.sub(k).color.mean.data()[e] - mean, 2);
    spread.data()[e] = float(squares / (K - 1) / K);
  }
  return spread;
}

void run(const std::string& renderPath, const std::string& referencePath, int radius) {
  const SampleBuffers buffers = sampleBuffersFromLayers(readExr(renderPath), renderPath);
  const Image reference = readRgbExr(referencePath);
  const int K = buffers.splitCount();
  if (K < 2) throw Error(renderPath + ": needs at least 2 sub-buffers (this render has 1)");
  const DenoiseInput full = buffers.input(BufferPart::Full);
  if (!reference.sameShape(full.whole.color.mean))
    throw Error(referencePath + ": its size differs from the render's");
  const Image& recordedVariance = full.whole.color.varianceOfMean;
  const double error = relMse(buffers.noisyColor(), reference);
  const double recorded = relativeMean(recordedVariance, reference);
  const double spread = relativeMean(subBufferSpread(buffers), reference);
  const double calibrated = relativeMean(calibratedWholeColorVariance(full, radius), reference);
  std::printf(
      "%s: K %d, error %.4g; recorded variance %.4g (%.2fx the error), sub-buffer spread "
      "%.4g (%.2fx), calibrated %.4g (%.2fx)\n",
      renderPath.c_str(), K, error, recorded, recorded / error, spread, spread / error, calibrated,
      calibrated / error);
}

}  // namespace
}  // namespace chorus

int main(int argc, char** argv) {
  CLI::App app("How well a render's recorded colour variance states its actual noise");
  std::string render, reference;
  int radius = 3;
  app.add_option("render", render, "a chorus render.exr with K >= 2 sub-buffers")->required();
  app.add_option("reference", reference, "a reference image of the same size")->required();
  app.add_option("--radius", radius, "the calibration's box radius")->check(CLI::Range(1, 64));
  return chorus::eval::parseAndRun(app, argc, argv, "variance_level",
                                   [&] { chorus::run(render, reference, radius); });
}
