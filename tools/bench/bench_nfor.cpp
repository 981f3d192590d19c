// bench_nfor: speed and quality of NFOR (with dual-buffer NL-means and RDFC next to it) on the
// Tungsten peer data (../shared/peers/tungsten-nfor).
//   speed:   seconds per megapixel on --threads threads (default 2), on one case's input
//            buffers tiled to --size × --size (default 1024 × 1024): wall and CPU (user + sys of
//            the process, i.e. summed over threads), and NFOR's speed-up per CPU-second over
//            Tungsten's NFOR (--tungsten-cpu CPU-s/Mpx on one thread, default 470); the fastest
//            of --repeats runs (default 1);
//   quality: relMSE against the reference for the nine cases, next to Tungsten's own NFOR
//            output, and how close our NFOR is to Tungsten's; the same split into the pixels
//            around highlights (within 4 px of a reference value > 0.6, the peers README's
//            definition) and the rest;
//   --outputs DIR: our NFOR outputs (the speed case and the nine quality cases) are compared
//            with DIR/<name>.exr where those exist (max |difference|, relMSE) and written there
//            where not — run once before a change and once after to see what it changed.
#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "common/memory_reuse.h"
#include "common/stopwatch.h"
#include "denoise/base/nfor/nfor.h"
#include "denoise/base/nlm/dual_buffer_nlm.h"
#include "denoise/base/rdfc/rdfc.h"
#include "denoise/buffers/tungsten_dir.h"
#include "denoise/metrics/metrics.h"
#include "tests/support/highlight_region.h"

namespace chorus {
namespace {

// `image` repeated to cover size × size (mirrored on odd tiles so that seams stay continuous).
Image tiled(const Image& image, int size) {
  Image out(size, size, image.channels());
  const int w = image.width(), h = image.height();
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const int tx = x / w, ty = y / h;
      const int sx = tx % 2 == 0 ? x % w : w - 1 - x % w;
      const int sy = ty % 2 == 0 ? y % h : h - 1 - y % h;
      for (int c = 0; c < image.channels(); ++c) out(x, y, c) = image(sx, sy, c);
    }
  return out;
}

SubBuffer tiled(const SubBuffer& b, int size) {
  SubBuffer out;
  for (Quantity q : kAllQuantities) {
    out.get(q).mean = tiled(b.get(q).mean, size);
    out.get(q).varianceOfMean = tiled(b.get(q).varianceOfMean, size);
  }
  out.sampleCount = tiled(b.sampleCount, size);
  return out;
}

DenoiseInput tiled(const DenoiseInput& in, int size) {
  DenoiseInput out;
  out.whole = tiled(in.whole, size);
  out.halves =
      std::array<SubBuffer, 2>{tiled(in.halves->at(0), size), tiled(in.halves->at(1), size)};
  return out;
}

struct Timing {
  double wall = 0, cpu = 0;  // seconds; cpu summed over all threads
};

template <typename Fn>
Timing timed(Fn&& fn) {
  const double cpu0 = processCpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  fn();
  return {std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
          processCpuSeconds() - cpu0};
}

// The fastest of `repeats` runs (by wall time): on a shared or virtual machine a run that another
// process slowed says nothing about the code.
template <typename Fn>
Timing fastest(int repeats, Fn&& fn) {
  Timing best = timed(fn);
  for (int i = 1; i < repeats; ++i) {
    const Timing t = timed(fn);
    if (t.wall < best.wall) best = t;
  }
  return best;
}

template <typename Fn>
double seconds(Fn&& fn) {
  return timed(fn).wall;
}

// Compares `image` with dir/name.exr if that exists, else writes it there. No-op for an empty dir.
void compareOrKeep(const std::filesystem::path& dir, const std::string& name, const Image& image) {
  if (dir.empty()) return;
  const std::filesystem::path path = dir / (name + ".exr");
  if (!std::filesystem::exists(path)) {
    std::filesystem::create_directories(dir);
    writeExr(path, image);
    return;
  }
  const Image before = readExrLayer(path);
  double maxDiff = 0, maxRel = 0;
  for (size_t i = 0; i < image.size(); ++i) {
    const double a = image.data()[i], b = before.data()[i], diff = std::abs(a - b);
    maxDiff = std::max(maxDiff, diff);
    maxRel = std::max(maxRel, diff / std::max(1e-3, std::abs(b)));
  }
  std::printf("  vs %s: max |diff| %.3e, max |diff|/max(1e-3, |before|) %.3e, relMSE %.3e\n",
              path.c_str(), maxDiff, maxRel, relMse(image, before));
}

int run(int argc, char** argv) {
  CLI::App app(
      "Speed (s/Mpx) of nfor, nlm and rdfc and quality (relMSE) of nfor and nlm on the "
      "Tungsten peer data");
  std::string shared = "../shared";
  int threads = 2, size = 1024, repeats = 1;
  std::string speedCase = "room/spp4";
  bool skipSpeed = false, skipQuality = false, skipNlm = false;
  double tungstenCpu = 470;
  bool nforOnly = false, rdfcOnly = false;
  std::string outputs;
  app.add_option("--shared", shared, "the shared data directory");
  app.add_option("--threads", threads, "TBB threads");
  app.add_option("--size", size, "side of the tiled image for the speed measurement");
  app.add_option("--case", speedCase, "the peer case tiled for the speed measurement");
  app.add_option("--repeats", repeats, "speed: runs per denoiser; the fastest is reported")
      ->check(CLI::Range(1, 100));
  app.add_flag("--skip-speed", skipSpeed);
  app.add_flag("--skip-quality", skipQuality);
  app.add_flag("--nfor-only", nforOnly, "speed: time NFOR only (for profiling)");
  app.add_flag("--rdfc-only", rdfcOnly, "speed: time RDFC only (for profiling)");
  app.add_flag("--skip-nlm", skipNlm, "quality: run NFOR only (the nlm column reads 0)");
  app.add_option("--tungsten-cpu", tungstenCpu,
                 "Tungsten's NFOR in CPU-s/Mpx (one thread; the peers' timings: 470-500)");
  app.add_option("--outputs", outputs, "compare our NFOR outputs with those kept here (or keep)");
  CLI11_PARSE(app, argc, argv);
  const std::filesystem::path root = std::filesystem::path(shared) / "peers/tungsten-nfor";
  if (!std::filesystem::is_directory(root)) throw fileError(root, "no such directory");
  tbb::global_control control(tbb::global_control::max_allowed_parallelism, size_t(threads));

  if (!skipSpeed) {
    const DenoiseInput input = tiled(readTungstenDirectory(root / speedCase), size);
    const double mpx = double(size) * size / 1e6;
    Image output;
    Timing nfor, nlm, rdfc;
    if (!rdfcOnly) nfor = fastest(repeats, [&] { output = NforDenoiser().run(input); });
    if (!nforOnly && !rdfcOnly) nlm = fastest(repeats, [&] { DualBufferNlMeans().run(input); });
    if (!nforOnly) rdfc = fastest(repeats, [&] { Rdfc().run(input); });
    // cpu / threads is what the wall clock would be on otherwise idle cores with perfect
    // scaling: a load-independent figure next to the wall clock.
    std::printf("speed: %s tiled to %dx%d, %d threads, fastest of %d run(s)\n", speedCase.c_str(),
                size, size, threads, repeats);
    std::printf("  %-6s %9s %9s %14s\n", "", "wall s/Mpx", "cpu s/Mpx", "cpu/threads");
    for (const auto& [name, t] :
         {std::pair{"nfor", nfor}, std::pair{"nlm", nlm}, std::pair{"rdfc", rdfc}})
      std::printf("  %-6s %9.2f %9.2f %14.2f\n", name, t.wall / mpx, t.cpu / mpx,
                  t.cpu / mpx / threads);
    if (!rdfcOnly) {
      std::printf("  nfor per CPU-second: %.1fx Tungsten's NFOR (%.0f CPU-s/Mpx)\n",
                  tungstenCpu / (nfor.cpu / mpx), tungstenCpu);
      compareOrKeep(outputs, "speed", output);
    }
  }
  if (!skipQuality) {
    std::printf(
        "quality (relMSE against reference.exr; frac = relMSE(ours, nfor.exr) / "
        "relMSE(noisy, nfor.exr))\n");
    std::printf(
        "  highlight columns: relMSE share of the pixels around highlights and the ratio "
        "ours / Tungsten there and elsewhere\n");
    std::printf("  %-10s %-6s %10s %10s %10s %7s %8s %10s %8s %8s %8s %8s\n", "scene", "spp",
                "noisy", "tungsten", "nfor", "ratio", "frac", "nlm", "nfor s", "hl share",
                "hl ratio", "rest");
    for (const char* scene : {"room", "glossy", "highlights"}) {
      const Image reference = readExrLayer(root / scene / "reference.exr");
      const std::vector<bool> mask = test::highlightMask(reference);
      for (const char* spp : {"spp4", "spp16", "spp64"}) {
        const auto dir = root / scene / spp;
        const DenoiseInput input = readTungstenDirectory(dir);
        const Image tungsten = readExrLayer(dir / "nfor.exr");
        Image ours;
        const double time = seconds([&] { ours = NforDenoiser().run(input); });
        const Image nlm = skipNlm ? tungsten : DualBufferNlMeans().run(input);
        const double oursRef = relMse(ours, reference), tungRef = relMse(tungsten, reference);
        const double tungHl = test::relMsePart(tungsten, reference, mask, true);
        const double oursHl = test::relMsePart(ours, reference, mask, true);
        const double tungRest = test::relMsePart(tungsten, reference, mask, false);
        const double oursRest = test::relMsePart(ours, reference, mask, false);
        std::printf(
            "  %-10s %-6s %10.6f %10.6f %10.6f %7.4f %8.4f %10.6f %8.2f %8.3f %8.4f %8.4f\n", scene,
            spp, relMse(input.whole.color.mean, reference), tungRef, oursRef, oursRef / tungRef,
            relMse(ours, tungsten) / relMse(input.whole.color.mean, tungsten),
            skipNlm ? 0.0 : relMse(nlm, reference), time, tungHl / tungRef, oursHl / tungHl,
            oursRest / tungRest);
        compareOrKeep(outputs, std::string(scene) + "_" + spp, ours);
      }
    }
  }
  return 0;
}

}  // namespace
}  // namespace chorus

int main(int argc, char** argv) {
  chorus::reuseFreedMemory();
  try {
    return chorus::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_nfor: %s\n", e.what());
    return 2;
  }
}
