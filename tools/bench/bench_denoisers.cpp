// bench_denoisers: seconds per megapixel and relMSE of every registered base denoiser.
//
// Cases (each a DenoiseInput plus a reference image):
//   synthetic  the procedural scene of tests/support/synthetic_scene.h (exact ground truth),
//              default 1024×1024, K = 4 sub-buffers × 4 spp, denoised on the full buffer.
// More case sources (rendered scenes at several spp) plug in as further `*Cases` functions.
//
// Every denoiser runs with its default parameters on `--threads` TBB threads (default 2); the
// time is the best of `--repeat` runs of BaseDenoiser::run (input preparation excluded).
#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "denoise/base/registry.h"
#include "denoise/metrics/metrics.h"
#include "denoise/util/error.h"
#include "tests/support/synthetic_scene.h"

namespace chorus::bench {
namespace {

struct BenchOptions {
  int size = 1024;
  int sppPerSubBuffer = 4;
  int threads = 2;
  int repeat = 1;
  float fireflyProbability = 0.0f;
  std::string methods;  // comma-separated specs; empty = every registered denoiser
};

struct BenchCase {
  std::string name;
  DenoiseInput input;
  Image reference;
};

std::vector<BenchCase> syntheticCases(const BenchOptions& o) {
  test::SyntheticSceneOptions scene;
  scene.width = scene.height = o.size;
  scene.samplesPerSubBuffer = o.sppPerSubBuffer;
  scene.fireflyProbability = o.fireflyProbability;
  const test::SyntheticScene s = test::makeSyntheticScene(scene);
  const int spp = scene.subBuffers * scene.samplesPerSubBuffer;
  return {{"synthetic " + std::to_string(o.size) + "² " + std::to_string(spp) + "spp",
           s.fullInput(), s.truth}};
}

std::vector<std::string> methodSpecs(const BenchOptions& o) {
  if (!o.methods.empty()) return splitMethodList(o.methods);
  std::vector<std::string> specs;
  for (const DenoiserEntry& entry : builtinDenoisers()) specs.push_back(entry.name);
  return specs;
}

struct Timing {
  double wallSeconds = 0, cpuSeconds = 0;
};

double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

Timing timeRun(const BaseDenoiser& denoiser, const DenoiseInput& input, Image& output) {
  const double cpuStart = processCpuSeconds();
  const auto start = std::chrono::steady_clock::now();
  output = denoiser.run(input);
  return {std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
          processCpuSeconds() - cpuStart};
}

void run(const BenchOptions& o) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, size_t(o.threads));
  const std::vector<std::string> specs = methodSpecs(o);
  std::vector<BenchCase> cases = syntheticCases(o);

  std::printf(
      "threads %d, best of %d run(s); cpu s/Mpx = CPU seconds of all threads (on a busy\n"
      "machine cpu / threads approximates the wall time of a quiet one)\n\n",
      o.threads, o.repeat);
  std::printf(
      "| case | method | s/Mpx | cpu s/Mpx | relMSE | relMSE noisy |\n"
      "|---|---|---:|---:|---:|---:|\n");
  for (const BenchCase& c : cases) {
    const double megapixels = double(c.input.width()) * c.input.height() / 1e6;
    const double noisy = relMse(c.input.whole.color.mean, c.reference);
    for (const std::string& spec : specs) {
      const auto denoiser = createDenoiser(spec);
      if (denoiser->requirements().halves && !c.input.halves) {
        std::printf("| %s | %s | (needs halves) | | | |\n", c.name.c_str(), spec.c_str());
        continue;
      }
      Image output;
      Timing best{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
      for (int r = 0; r < o.repeat; ++r) {
        const Timing t = timeRun(*denoiser, c.input, output);
        best.wallSeconds = std::min(best.wallSeconds, t.wallSeconds);
        best.cpuSeconds = std::min(best.cpuSeconds, t.cpuSeconds);
      }
      std::printf("| %s | %s | %.3f | %.3f | %.5f | %.5f |\n", c.name.c_str(), spec.c_str(),
                  best.wallSeconds / megapixels, best.cpuSeconds / megapixels,
                  relMse(output, c.reference), noisy);
      std::fflush(stdout);
    }
  }
}

}  // namespace
}  // namespace chorus::bench

int main(int argc, char** argv) {
  chorus::bench::BenchOptions o;
  CLI::App app{"Seconds per megapixel and relMSE of every registered base denoiser"};
  app.add_option("--size", o.size, "synthetic image width and height")->check(CLI::Range(8, 8192));
  app.add_option("--spp", o.sppPerSubBuffer, "synthetic samples per sub-buffer (K = 4)")
      ->check(CLI::Range(1, 1024));
  app.add_option("--threads", o.threads, "TBB threads")->check(CLI::Range(1, 256));
  app.add_option("--repeat", o.repeat, "runs per denoiser (the best is reported)")
      ->check(CLI::Range(1, 100));
  app.add_option("--fireflies", o.fireflyProbability,
                 "probability of a firefly sample (×200) in the synthetic scene")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--methods", o.methods, "comma-separated denoiser specs (default: all)");
  CLI11_PARSE(app, argc, argv);
  try {
    chorus::bench::run(o);
  } catch (const chorus::Error& e) {
    std::cerr << "bench_denoisers: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
