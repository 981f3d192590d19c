// bench_denoisers: seconds per megapixel and relMSE of every registered base denoiser.
//
// Case sources (`--cases`, comma-separated; default synthetic,rendered):
//   synthetic  the procedural scene of tests/support/synthetic_scene.h with exact ground truth,
//              default 1024×1024, K = 4 sub-buffers × 4 spp (the timing case)
//   rendered   scenes rendered in-process by the chorus renderer at each of `--spp` (default
//              4,16,64; K = 4; width `--render-width`, default 160), against a reference
//              rendered with `--reference-spp` samples (default 4096; `--reference-cache DIR`
//              keeps it for the next run):
//              the default scene (scenes/cornell-box.gltf) and ../shared/scenes/FlightHelmet-Bevy
//              lit by ../shared/scenes/_environments/studio_small_05_1k.hdr (skipped without
//              ../shared)
//   peers      the Tungsten NFOR peer buffers in ../shared/peers/tungsten-nfor (room and glossy
//              at 4/16/64 spp, with their references)
// Every denoiser runs with its default parameters on `--threads` TBB threads (default 2) on the
// full buffer; the time is the best of `--repeat` runs of BaseDenoiser::run. `--oracle` adds,
// per case, the relMSE of choosing per pixel the best output (using the reference): with all
// methods and with each one left out — how much each member could add to an ensemble.
// `--save-outputs DIR` writes every output to DIR/<case>-<method>.exr; `--compare-to DIR` prints
// each output's largest absolute and relative difference from such a saved one (a speed change
// should move them by float rounding only).
#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/memory_reuse.h"
#include "common/stopwatch.h"
#include "denoise/base/registry.h"
#include "denoise/buffers/tungsten_dir.h"
#include "denoise/metrics/metrics.h"
#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tests/support/synthetic_scene.h"
#include "tools/sweep/reference_render.h"

namespace chorus::bench {
namespace {
namespace fs = std::filesystem;

struct BenchOptions {
  std::string cases = "synthetic,rendered";
  int size = 1024;
  int sppPerSubBuffer = 4;
  float fireflyProbability = 0.0f;
  std::string spp = "4,16,64";
  int renderWidth = 160;
  int referenceSpp = 4096;
  std::string referenceCache;  // directory of cached reference renders ("" = none)
  int threads = 2;
  int repeat = 1;
  bool oracle = false;
  std::string methods;                 // comma-separated specs; empty = every registered denoiser
  std::string saveOutputs, compareTo;  // directories ("" = none)
};

struct BenchCase {
  std::string name;
  DenoiseInput input;
  Image reference;
};

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ','))
    if (!item.empty()) items.push_back(item);
  return items;
}

fs::path sourceDir() {
  return fs::path(__FILE__).parent_path().parent_path().parent_path();
}

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

std::vector<BenchCase> renderedCases(const BenchOptions& o) {
  struct SceneSpec {
    std::string name;
    fs::path gltf, environment;
  };
  std::vector<SceneSpec> scenes = {{"cornell-box", sourceDir() / "scenes/cornell-box.gltf", {}}};
  const fs::path shared = sourceDir().parent_path() / "shared/scenes";
  if (fs::is_directory(shared))
    scenes.push_back({"flight-helmet+studio", shared / "FlightHelmet-Bevy/FlightHelmet.gltf",
                      shared / "_environments/studio_small_05_1k.hdr"});
  else
    std::fprintf(stderr, "bench_denoisers: %s absent, rendering the default scene only\n",
                 shared.c_str());

  std::vector<BenchCase> cases;
  for (const SceneSpec& spec : scenes) {
    const render::Scene scene = render::buildScene(
        render::loadGltf(spec.gltf), spec.environment.empty()
                                         ? render::EnvironmentDesc{}
                                         : render::environmentFromFile(spec.environment));
    render::RenderOptions options;
    options.width = o.renderWidth;
    options.threads = o.threads;
    options.spp = o.referenceSpp;
    const fs::path cached =
        o.referenceCache.empty()
            ? fs::path()
            : fs::path(o.referenceCache) / (spec.name + "-" + std::to_string(o.renderWidth) + "-" +
                                            std::to_string(o.referenceSpp) + "spp.exr");
    const Image reference =
        sweep::referenceRender(scene, options, cached, "bench_denoisers " + spec.name);
    for (const std::string& spp : splitList(o.spp)) {
      options.spp = std::stoi(spp);
      options.splits = 4;
      options.seed = 1;
      cases.push_back({spec.name + " " + spp + "spp",
                       render::render(scene, options).buffers.input(BufferPart::Full), reference});
    }
  }
  return cases;
}

std::vector<BenchCase> peerCases() {
  const fs::path peers = sourceDir().parent_path() / "shared/peers/tungsten-nfor";
  std::vector<BenchCase> cases;
  if (!fs::is_directory(peers)) {
    std::fprintf(stderr, "bench_denoisers: %s absent, no peer cases\n", peers.c_str());
    return cases;
  }
  for (const char* scene : {"room", "glossy"}) {
    const Image reference = readExrLayer(peers / scene / "reference.exr");
    for (const char* spp : {"4", "16", "64"})
      cases.push_back({std::string("tungsten ") + scene + " " + spp + "spp",
                       readTungstenDirectory(peers / scene / (std::string("spp") + spp)),
                       reference});
  }
  return cases;
}

struct Timing {
  double wallSeconds = 0, cpuSeconds = 0;
};

Timing timeRun(const BaseDenoiser& denoiser, const DenoiseInput& input, Image& output) {
  const double cpuStart = processCpuSeconds();
  const auto start = std::chrono::steady_clock::now();
  output = denoiser.run(input);
  return {std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
          processCpuSeconds() - cpuStart};
}

// Output file of one case and method: its index in the case list and the method spec.
fs::path outputPath(const std::string& dir, size_t caseIndex, const std::string& spec) {
  std::string name = std::to_string(caseIndex) + "-" + spec;
  for (char& ch : name)
    if (ch == '/' || ch == ' ') ch = '_';
  return fs::path(dir) / (name + ".exr");
}

// Largest |a − b| and |a − b| / max(|a|, |b|) over all values (0 / 0 counts as 0).
void printDifference(const std::string& what, const Image& a, const Image& b) {
  if (!a.sameShape(b)) {
    std::printf("  %s: shapes differ\n", what.c_str());
    return;
  }
  double maxAbs = 0, maxRel = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    const double x = a.data()[k], y = b.data()[k], d = std::abs(x - y);
    const double scale = std::max(std::abs(x), std::abs(y));
    maxAbs = std::max(maxAbs, d);
    if (scale > 0) maxRel = std::max(maxRel, d / scale);
  }
  std::printf("  %s: max |diff| %.3g, max rel diff %.3g, relMSE against it %.5g\n", what.c_str(),
              maxAbs, maxRel, relMse(a, b));
}

// relMSE of the per-pixel best of `outputs` (those with include[i]), judged by the reference.
double oracleRelMse(const std::vector<Image>& outputs, const std::vector<bool>& include,
                    const Image& reference) {
  double sum = 0;
  for (int y = 0; y < reference.height(); ++y)
    for (int x = 0; x < reference.width(); ++x) {
      double best = std::numeric_limits<double>::infinity();
      for (size_t i = 0; i < outputs.size(); ++i) {
        if (!include[i]) continue;
        double e = 0;
        for (int c = 0; c < 3; ++c) {
          const double r = reference(x, y, c), d = outputs[i](x, y, c) - r;
          e += d * d / (r * r + kRelMseEpsilon);
        }
        best = std::min(best, e);
      }
      sum += best;
    }
  return sum / (3.0 * double(reference.pixelCount()));
}

void printOracle(const BenchCase& c, const std::vector<std::string>& specs,
                 const std::vector<Image>& outputs) {
  if (outputs.size() < 2) return;
  std::vector<bool> include(outputs.size(), true);
  std::printf("| %s | oracle per-pixel best of all | | | %.5f | |\n", c.name.c_str(),
              oracleRelMse(outputs, include, c.reference));
  for (size_t i = 0; i < outputs.size(); ++i) {
    include.assign(outputs.size(), true);
    include[i] = false;
    std::printf("| %s | oracle without %s | | | %.5f | |\n", c.name.c_str(), specs[i].c_str(),
                oracleRelMse(outputs, include, c.reference));
  }
}

void run(const BenchOptions& o) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, size_t(o.threads));
  const std::vector<std::string> specs =
      o.methods.empty() ? std::vector<std::string>{} : splitMethodList(o.methods);
  std::vector<std::string> methods = specs;
  if (methods.empty())
    for (const DenoiserEntry& entry : builtinDenoisers()) methods.push_back(entry.name);

  std::vector<BenchCase> cases;
  for (const std::string& source : splitList(o.cases)) {
    std::vector<BenchCase> more;
    if (source == "synthetic") {
      more = syntheticCases(o);
    } else if (source == "rendered") {
      more = renderedCases(o);
    } else if (source == "peers") {
      more = peerCases();
    } else {
      throw Error("unknown case source '" + source + "' (synthetic, rendered, peers)");
    }
    for (BenchCase& c : more) cases.push_back(std::move(c));
  }

  std::printf(
      "threads %d, best of %d run(s); cpu s/Mpx = CPU seconds of all threads (on a busy\n"
      "machine cpu / threads approximates the wall time of a quiet one)\n\n",
      o.threads, o.repeat);
  std::printf(
      "| case | method | s/Mpx | cpu s/Mpx | relMSE | relMSE noisy |\n"
      "|---|---|---:|---:|---:|---:|\n");
  for (size_t caseIndex = 0; caseIndex < cases.size(); ++caseIndex) {
    const BenchCase& c = cases[caseIndex];
    const double megapixels = double(c.input.width()) * c.input.height() / 1e6;
    const double noisy = relMse(c.input.whole.color.mean, c.reference);
    std::vector<Image> outputs;
    std::vector<std::string> ran;
    for (const std::string& spec : methods) {
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
      std::printf("| %s | %s | %.3f | %.3f | %.5g | %.5g |\n", c.name.c_str(), spec.c_str(),
                  best.wallSeconds / megapixels, best.cpuSeconds / megapixels,
                  relMse(output, c.reference), noisy);
      std::fflush(stdout);
      if (!o.saveOutputs.empty()) {
        fs::create_directories(o.saveOutputs);
        writeExr(outputPath(o.saveOutputs, caseIndex, spec), output);
      }
      outputs.push_back(std::move(output));
      ran.push_back(spec);
    }
    if (o.oracle) printOracle(c, ran, outputs);
    if (!o.compareTo.empty()) {
      std::printf("\ndifferences from %s:\n", o.compareTo.c_str());
      for (size_t i = 0; i < ran.size(); ++i)
        printDifference(c.name + " " + ran[i], outputs[i],
                        readRgbExr(outputPath(o.compareTo, caseIndex, ran[i])));
    }
  }
}

}  // namespace
}  // namespace chorus::bench

int main(int argc, char** argv) {
  chorus::reuseFreedMemory();
  chorus::bench::BenchOptions o;
  CLI::App app{"Seconds per megapixel and relMSE of every registered base denoiser"};
  app.add_option("--cases", o.cases, "case sources: synthetic, rendered, peers (comma-separated)");
  app.add_option("--size", o.size, "synthetic image width and height")->check(CLI::Range(8, 8192));
  app.add_option("--synthetic-spp", o.sppPerSubBuffer, "synthetic samples per sub-buffer (K = 4)")
      ->check(CLI::Range(1, 1024));
  app.add_option("--fireflies", o.fireflyProbability,
                 "probability of a firefly sample (×200) in the synthetic scene")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--spp", o.spp, "rendered cases: samples per pixel, comma-separated");
  app.add_option("--render-width", o.renderWidth, "rendered cases: image width")
      ->check(CLI::Range(8, 4096));
  app.add_option("--reference-spp", o.referenceSpp, "rendered cases: reference samples per pixel")
      ->check(CLI::Range(1, 1 << 20));
  app.add_option("--reference-cache", o.referenceCache,
                 "rendered cases: directory to keep reference renders in and reuse them from");
  app.add_option("--threads", o.threads, "TBB threads")->check(CLI::Range(1, 256));
  app.add_option("--repeat", o.repeat, "runs per denoiser (the best is reported)")
      ->check(CLI::Range(1, 100));
  app.add_flag("--oracle", o.oracle, "per-pixel oracle selection, with each method left out");
  app.add_option("--methods", o.methods, "comma-separated denoiser specs (default: all)");
  app.add_option("--save-outputs", o.saveOutputs, "directory to write every output to (EXR)");
  app.add_option("--compare-to", o.compareTo,
                 "directory of outputs saved by --save-outputs: print the largest differences");
  CLI11_PARSE(app, argc, argv);
  try {
    chorus::bench::run(o);
  } catch (const chorus::Error& e) {
    std::cerr << "bench_denoisers: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
