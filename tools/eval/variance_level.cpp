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
#include "tools/eval/tool_main.h"

namespace chorus {
namespace {

void run(const std::string& renderPath, const std::string& referencePath, int radius) {
  const SampleBuffers buffers = sampleBuffersFromLayers(readExr(renderPath), renderPath);
  const Image reference = readRgbExr(referencePath);
  const int K = buffers.splitCount();
  if (K < 2) throw Error(renderPath + ": needs at least 2 sub-buffers (this render has 1)");
  const DenoiseInput full = buffers.input(BufferPart::Full);
  if (!reference.sameShape(full.whole.color.mean))
    throw Error(referencePath + ": its size differs from the render's");
  const Image calibrated =
      calibratedVariance(full.whole.color.varianceOfMean, colorVarianceCalibration(full, radius));
  double error = 0, recorded = 0, spread = 0, calibratedSum = 0;
  long n = 0;
  for (int y = 0; y < reference.height(); ++y)
    for (int x = 0; x < reference.width(); ++x)
      for (int c = 0; c < 3; ++c, ++n) {
        const double r = reference(x, y, c), weight = 1.0 / (r * r + 0.01);
        const double e = full.whole.color.mean(x, y, c) - r;
        error += weight * e * e;
        recorded += weight * full.whole.color.varianceOfMean(x, y, c);
        calibratedSum += weight * calibrated(x, y, c);
        double mean = 0, squares = 0;
        for (int k = 0; k < K; ++k) mean += buffers.sub(k).color.mean(x, y, c);
        mean /= K;
        for (int k = 0; k < K; ++k)
          squares += std::pow(buffers.sub(k).color.mean(x, y, c) - mean, 2);
        spread += weight * squares / (K - 1) / K;  // the variance of the mean of K means
      }
  std::printf(
      "%s: K %d, error %.4g; recorded variance %.4g (%.2fx the error), sub-buffer spread "
      "%.4g (%.2fx), calibrated %.4g (%.2fx)\n",
      renderPath.c_str(), K, error / n, recorded / n, recorded / error, spread / n, spread / error,
      calibratedSum / n, calibratedSum / error);
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
