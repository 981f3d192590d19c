// Times the ensemble's combination step (solve + weight filter + blend) on 1 megapixel with
// N = 4 base outputs (with their held-out runs: the default estimate compares them with the
// quarters), for the default path (MSE window), the halves estimate and per pixel (the paper's
// form), and
// prints seconds per megapixel (wall clock, and process CPU time: on a busy machine the CPU
// time divided by the thread count is the better estimate of the quiet-machine wall time). Base
// outputs are separable box blurs of a synthetic render (their cost is not measured here). The
// "mse" and "xbf" columns time, in separate passes, the MSE estimate alone (part of "solve") and
// the joint-bilateral filter of the weights alone (the core of "filter"), wall and CPU; the
// "digest" column hashes the output image and weights, so that a speed change that should not
// change results can be checked bit for bit. Never run by CTest.
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <span>
#include <string>
#include <vector>

#include "common/memory_reuse.h"
#include "common/stopwatch.h"
#include "denoise/ensemble/combiners.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/held_out_inputs.h"
#include "tests/support/synthetic_cases.h"

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

// FNV-1a over the bits of the blend and the final weights.
uint64_t digest(const CombineResult& result) {
  uint64_t hash = 1469598103934665603ull;
  const auto add = [&](const Image& image) {
    for (float v : image.values()) {
      hash ^= std::bit_cast<uint32_t>(v);
      hash *= 1099511628211ull;
    }
  };
  add(result.image);
  for (const Image& map : result.weights) add(map);
  return hash;
}

// Wall and process CPU seconds of a piece of work.
struct Timing {
  double wall = 1e30, cpu = 1e30;
};
template <typename Work>
Timing timed(Work&& work) {
  const std::clock_t cpuStart = std::clock();
  Stopwatch clock;
  work();
  return {clock.seconds(), double(std::clock() - cpuStart) / CLOCKS_PER_SEC};
}

// The MSE estimate of the whole image in bands, as the solve stage computes it.
Timing timeMseEstimate(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases,
                       const MseOptions& options) {
  const MseEstimator estimator(guides, bases, options);
  constexpr int kBandRows = 32;
  const int bands = (estimator.height() + kBandRows - 1) / kBandRows;
  return timed([&] {
    tbb::parallel_for(0, bands, [&](int band) {
      const MseRows rows = estimator.rows(band * kBandRows, (band + 1) * kBandRows);
      (void)rows;
    });
  });
}

// The joint-bilateral filter of the raw weights alone (the core of the filter stage).
Timing timeWeightFilter(const CombineResult& result, const EnsembleGuides& guides,
                        const WeightFilterOptions& options) {
  const ColorGuide guide = makeColorGuide(result.image, result.imageA, result.imageB, options);
  return timed([&] {
    const std::vector<Image> filtered =
        crossBilateralFilter(result.rawWeights, guide, guides.normal, guides.albedo, options);
  });
}

}  // namespace

int main(int argc, char** argv) {
  chorus::reuseFreedMemory();
  CLI::App app{"ensemble combination step: seconds per megapixel"};
  int size = 1024, threads = 2, repeats = 3;
  std::string only;
  app.add_option("--size", size, "image width and height (default 1024: 1 Mpx)");
  app.add_option("--threads", threads, "TBB threads (default 2)");
  app.add_option("--repeats", repeats, "runs per configuration; the fastest is reported");
  app.add_option("--only", only, "run only the configurations whose name starts with this");
  CLI11_PARSE(app, argc, argv);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

  const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Regions, size, size);
  const synthetic::NoiseModel noise{1.0f, 4, 0.0f};
  const SampleBuffers buffers = synthetic::renderBuffers(scene, noise, 4, 7);
  const EnsembleSources sources = sourcesFromBuffers(buffers);
  const EnsembleGuides guides = guidesFromSources(sources, true);
  const std::vector<DenoiseInput> heldOut = heldOutInputs(sources);
  std::vector<BaseOutputs> bases;
  const int radii[4] = {1, 2, 4, 2};
  const float clamps[4] = {0, 0, 0, 0.5f};
  for (int i = 0; i < 4; ++i) {
    bases.push_back({"box" + std::to_string(radii[i]) + (clamps[i] > 0 ? "clamped" : ""),
                     boxBlur(guides.colorA, radii[i], clamps[i]),
                     boxBlur(guides.colorB, radii[i], clamps[i]),
                     boxBlur(guides.color, radii[i], clamps[i]),
                     {}});
    for (const DenoiseInput& input : heldOut)
      bases.back().heldOut.push_back(boxBlur(input.whole.color.mean, radii[i], clamps[i]));
  }
  const auto pointers = pointersTo(bases);
  const double megapixels = double(size) * size / 1e6;

  struct Config {
    std::string name;
    CombineOptions options;
  };
  std::vector<Config> configs;
  configs.push_back({"default (summed, MSE window r=5, filter r=7)", {}});
  CombineOptions halves;
  halves.mse.estimate = MseEstimate::Halves;
  configs.push_back({"halves estimate (else the defaults)", halves});
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
  std::printf("%-44s %6s %6s %6s %7s %9s | %11s %11s | %s\n", "configuration (seconds)", "solve",
              "filter", "blend", "s/Mpx", "cpu s/Mpx", "mse wall/cpu", "xbf wall/cpu", "digest");
  for (const Config& config : configs) {
    if (config.name.rfind(only, 0) != 0) continue;
    double best = 1e30, solve = 0, filter = 0, blendTime = 0, cpu = 0;
    Timing mse, bilateral;
    uint64_t hash = 0;
    for (int r = 0; r < repeats; ++r) {
      const Timing m = timeMseEstimate(guides, pointers, config.options.mse);
      if (m.wall < mse.wall) mse = m;
      CombineResult result;
      const Timing all = timed([&] { result = combine(guides, pointers, config.options); });
      double total = 0;
      for (const StageTime& t : result.times) total += t.seconds;
      if (total < best) {
        best = total;
        cpu = all.cpu;
        solve = result.times[0].seconds;
        filter = result.times[1].seconds;
        blendTime = result.times[2].seconds;
      }
      const Timing b = timeWeightFilter(result, guides, config.options.filter);
      if (b.wall < bilateral.wall) bilateral = b;
      hash = digest(result);
    }
    std::printf("%-44s %6.3f %6.3f %6.3f %7.3f %9.3f | %5.3f/%5.3f %5.3f/%5.3f | %016llx\n",
                config.name.c_str(), solve, filter, blendTime, best / megapixels, cpu / megapixels,
                mse.wall, mse.cpu, bilateral.wall, bilateral.cpu,
                static_cast<unsigned long long>(hash));
  }
  return 0;
}
