// Times the ensemble's combination step (solve + weight filter + blend) on 1 megapixel with
// N = 4 base outputs, for the default path (MSE window) and per pixel (the paper's form), and
// prints seconds per megapixel (wall clock, and process CPU time: on a busy machine the CPU
// time divided by the thread count is the better estimate of the quiet-machine wall time). Base
// outputs are separable box blurs of a synthetic render (their cost is not measured here). Never
// run by CTest.
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "denoise/ensemble/combiners.h"
#include "denoise/ensemble/synthetic_cases.h"
#include "denoise/metrics/metrics.h"

namespace {
using namespace chorus;

// Box blur of radius r (clipped at the borders), optionally clamping values first.
Image boxBlur(const Image& image, int r, float clampValue) {
  const int w = image.width(), h = image.height();
  Image clamped = image, horizontal(w, h, 3), out(w, h, 3);
  if (clampValue > 0)
    for (float& v : clamped.values()) v = std::min(v, clampValue);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        double sum = 0;
        int count = 0;
        for (int d = std::max(-r, -x); d <= std::min(r, w - 1 - x); ++d, ++count)
          sum += clamped(x + d, y, c);
        horizontal(x, y, c) = float(sum / count);
      }
  });
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        double sum = 0;
        int count = 0;
        for (int d = std::max(-r, -y); d <= std::min(r, h - 1 - y); ++d, ++count)
          sum += horizontal(x, y + d, c);
        out(x, y, c) = float(sum / count);
      }
  });
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ensemble combination step: seconds per megapixel"};
  int size = 1024, threads = 2, repeats = 3;
  app.add_option("--size", size, "image width and height (default 1024: 1 Mpx)");
  app.add_option("--threads", threads, "TBB threads (default 2)");
  app.add_option("--repeats", repeats, "runs per configuration; the fastest is reported");
  CLI11_PARSE(app, argc, argv);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

  const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Regions, size, size);
  const synthetic::NoiseModel noise{1.0f, 4, 0.0f};
  const SampleBuffers buffers = synthetic::renderBuffers(scene, noise, 4, 7);
  const EnsembleSources sources = sourcesFromBuffers(buffers);
  const EnsembleGuides guides = guidesFromSources(sources);
  std::vector<BaseOutputs> bases;
  const int radii[4] = {1, 2, 4, 2};
  const float clamps[4] = {0, 0, 0, 0.5f};
  for (int i = 0; i < 4; ++i)
    bases.push_back({"box" + std::to_string(radii[i]) + (clamps[i] > 0 ? "clamped" : ""),
                     boxBlur(guides.colorA, radii[i], clamps[i]),
                     boxBlur(guides.colorB, radii[i], clamps[i]),
                     boxBlur(guides.color, radii[i], clamps[i])});
  const auto pointers = pointersTo(bases);
  const double megapixels = double(size) * size / 1e6;

  struct Config {
    std::string name;
    CombineOptions options;
  };
  std::vector<Config> configs;
  configs.push_back({"default (summed, MSE window r=5, filter r=7)", {}});
  CombineOptions perPixel;
  perPixel.mse.windowRadius = 0;
  configs.push_back({"per pixel (summed, window 0, filter r=7)", perPixel});
  CombineOptions perChannel;
  perChannel.mse.form = MseForm::PerChannel;
  perChannel.mse.windowRadius = 0;
  configs.push_back({"paper (per channel, window 0, filter r=7)", perChannel});
  CombineOptions perChannelWindow;
  perChannelWindow.mse.form = MseForm::PerChannel;
  configs.push_back({"per channel, window r=5, filter r=7", perChannelWindow});
  CombineOptions pairwise = perChannel;
  pairwise.solver = SolverKind::Pairwise;
  configs.push_back({"paper with the pairwise solver", pairwise});

  std::printf("%dx%d (%.2f Mpx), N = 4, %d threads, best of %d\n", size, size, megapixels, threads,
              repeats);
  std::printf("%-48s %8s %8s %8s %9s %9s %9s\n", "configuration", "solve", "filter", "blend",
              "total s", "s/Mpx", "cpu s/Mpx");
  for (const Config& config : configs) {
    double best = 1e30, solve = 0, filter = 0, blendTime = 0, cpu = 0;
    for (int r = 0; r < repeats; ++r) {
      const std::clock_t cpuStart = std::clock();
      const CombineResult result = combine(guides, pointers, config.options);
      const double cpuSeconds = double(std::clock() - cpuStart) / CLOCKS_PER_SEC;
      double total = 0;
      for (const StageTime& t : result.times) total += t.seconds;
      if (total < best) {
        best = total;
        cpu = cpuSeconds;
        solve = result.times[0].seconds;
        filter = result.times[1].seconds;
        blendTime = result.times[2].seconds;
      }
    }
    std::printf("%-48s %8.3f %8.3f %8.3f %9.3f %9.3f %9.3f\n", config.name.c_str(), solve, filter,
                blendTime, best, best / megapixels, cpu / megapixels);
  }
  return 0;
}
