// Scaling of the denoising stage (not a test; prints figures, issue 28.5, docs/leave-out.md):
//   1. denoise time (members on half A, half B and the full buffer, then solve, filter and
//      blend: what `chorus render` does after rendering) against the pixel count, with the
//      default members, at --sizes (square images); sizes in --extrapolate are not run but
//      extrapolated from the largest measured one at its seconds per megapixel (every member is
//      a local filter: its work is linear in the pixels, which the measured sizes check);
//   2. the same stage against the member count, at --member-size, for each list of
//      --member-lists;
//   3. the working set of `chorus render` with the default members at 1920x1080 and 3840x2160
//      from tools/chorus/memory_estimate (calibrated against peak RSS, docs/hardening-cli.md),
//      against the machine's memory.
// The renders record only the planes the members read (as `chorus render` does) and use few
// samples: no member's time depends on the sample count. Wall and process CPU seconds are
// printed; on a shared machine the CPU seconds are the steadier figure.
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "common/memory_reuse.h"
#include "common/stopwatch.h"
#include "denoise/base/registry.h"
#include "denoise/pipeline/ensemble.h"
#include "denoise/pipeline/member_planes.h"
#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tools/chorus/memory_estimate.h"
#include "tools/chorus/render_denoise.h"

namespace {

using namespace chorus;

double peakRssMiB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

struct Timing {
  double wall = 0, cpu = 0, bases = 0, combine = 0;
};

// Renders `size`² for `members` (their planes and splits) and times the denoising stage.
Timing timeDenoise(const render::Scene& scene, int size, int spp, int threads,
                   const std::string& list) {
  const Ensemble ensemble(membersFromSpecs(splitMethodList(list)), {});
  render::RenderOptions options;
  options.width = options.height = size;
  options.spp = spp;
  options.threads = threads;
  options.splits = splitsNeeded(ensemble.members());
  options.planes = planesReadBy(ensemble.members(), true);
  render::RenderResult rendered = render::render(scene, options);
  const EnsembleSources sources =
      sourcesFromBuffers(std::move(rendered.buffers), readsHalves(ensemble.members()));
  Timing t;
  const double cpu0 = processCpuSeconds();
  const Stopwatch wall;
  const EnsembleResult result = ensemble.run(sources);
  t.wall = wall.seconds();
  t.cpu = processCpuSeconds() - cpu0;
  for (const StageTime& s : result.times)
    if (s.stage == "bases") t.bases = s.seconds;
  t.combine = t.wall - t.bases;
  return t;
}

std::vector<std::string> splitOn(const std::string& text, char separator) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, separator))
    if (!item.empty()) items.push_back(item);
  return items;
}

double mpx(int width, int height) {
  return double(width) * double(height) / 1e6;
}

}  // namespace

int main(int argc, char** argv) {
  chorus::reuseFreedMemory();
  CLI::App app("Denoise time against pixels and member count; working set at 1080p and 4K");
  std::string scenePath = "scenes/cornell-box.gltf", members = cli::kDefaultDenoise;
  std::string memberLists =
      "atrous;rdfc,atrous;nfor,rdfc,atrous;nfor,rdfc,atrous,jnlm;"
      "nfor,rdfc,atrous,jnlm,sbf;nfor,rdfc,atrous,jnlm,sbf,nlm,bilateral";
  std::vector<int> sizes = {256, 512, 1024}, extrapolate = {2048};
  int spp = 4, threads = 2, memberSize = 256;
  app.add_option("--scene", scenePath, "glTF scene")->capture_default_str();
  app.add_option("--members", members, "Members timed against the pixel count")
      ->capture_default_str();
  app.add_option("--sizes", sizes, "Square sizes measured")->delimiter(',')->capture_default_str();
  app.add_option("--extrapolate", extrapolate, "Square sizes extrapolated (not run)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--member-lists", memberLists, "Member lists (';'-separated) timed at one size")
      ->capture_default_str();
  app.add_option("--member-size", memberSize, "Square size of the member-count runs")
      ->capture_default_str();
  app.add_option("--spp", spp, "Samples per pixel of the renders")->capture_default_str();
  app.add_option("--threads", threads, "Threads")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  tbb::global_control control(tbb::global_control::max_allowed_parallelism, size_t(threads));
  const render::Scene scene = render::buildScene(render::loadGltf(scenePath), {});

  std::printf("1. denoise time against pixels: %s, %s, %d spp, %d threads\n", members.c_str(),
              scenePath.c_str(), spp, threads);
  std::printf("  %-11s %7s %8s %8s %8s %8s %9s %9s\n", "size", "Mpx", "wall s", "cpu s", "members",
              "combine", "wall s/Mpx", "cpu s/Mpx");
  double wallPerMpx = 0, cpuPerMpx = 0;
  for (int size : sizes) {
    const Timing t = timeDenoise(scene, size, spp, threads, members);
    const double m = mpx(size, size);
    wallPerMpx = t.wall / m;
    cpuPerMpx = t.cpu / m;
    std::printf("  %4dx%-6d %7.3f %8.2f %8.2f %8.2f %8.2f %9.2f %9.2f\n", size, size, m, t.wall,
                t.cpu, t.bases, t.combine, wallPerMpx, cpuPerMpx);
    std::fflush(stdout);
  }
  for (int size : extrapolate) {
    const double m = mpx(size, size);
    std::printf("  %4dx%-6d %7.3f %8.1f %8.1f %8s %8s %9s %9s  (extrapolated at the last s/Mpx)\n",
                size, size, m, wallPerMpx * m, cpuPerMpx * m, "", "", "", "");
  }
  std::printf("  peak RSS of this process so far: %.0f MiB\n", peakRssMiB());

  std::printf("2. denoise time against member count at %dx%d, %d spp, %d threads\n", memberSize,
              memberSize, spp, threads);
  std::printf("  %-3s %8s %8s %8s %8s  %s\n", "N", "wall s", "cpu s", "members", "combine",
              "members");
  for (const std::string& list : splitOn(memberLists, ';')) {
    const Timing t = timeDenoise(scene, memberSize, spp, threads, list);
    std::printf("  %-3zu %8.2f %8.2f %8.2f %8.2f  %s\n", splitMethodList(list).size(), t.wall,
                t.cpu, t.bases, t.combine, list.c_str());
    std::fflush(stdout);
  }

  std::printf("3. working set of `chorus render` with %s (tools/chorus/memory_estimate)\n",
              cli::kDefaultDenoise);
  const std::vector<EnsembleMember> defaults =
      membersFromSpecs(splitMethodList(cli::kDefaultDenoise));
  const int splits = splitsNeeded(defaults);
  for (const render::Resolution size :
       {render::Resolution{1920, 1080}, render::Resolution{3840, 2160}}) {
    const double gib = double(cli::estimatePeakBytes(size, splits, defaults)) / double(1 << 30);
    std::printf("  %4dx%-5d K = %d: %.2f GiB estimated, %s 24 GiB\n", size.width, size.height,
                splits, gib, gib <= 24.0 ? "fits in" : "exceeds");
  }
  return 0;
}
