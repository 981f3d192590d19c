// Preview latency (not a test; prints figures): what `chorus render --preview` does after the
// scene is loaded — render at 4 spp with K = 4, run the preview members on half A, half B and
// the full buffer, solve and blend (previews skip the weight filter), encode the PNG — timed
// end to end (best and median of --repeat runs, wall clock and process CPU time), on
// scenes/cornell-box.gltf at 512×512 by default. The target is ≤ 1.0 s wall on 2 cores. Then the
// relMSE it reaches against a high-spp reference (cached with --reference-cache), next to the noisy
// input and the full default ensemble (`chorus render`'s default members) at the same spp.
#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "common/image/png_io.h"
#include "common/memory_reuse.h"
#include "common/stopwatch.h"
#include "denoise/base/registry.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tools/chorus/render_denoise.h"
#include "tools/sweep/reference_render.h"

namespace {

using namespace chorus;

struct Run {
  double wall = 0, cpu = 0, render = 0, bases = 0, combine = 0, png = 0;
  Image image, noisy;
};

Run runOnce(const render::Scene& scene, const render::RenderOptions& options,
            const Ensemble& ensemble) {
  Run run;
  const double cpu0 = processCpuSeconds();
  Stopwatch total, stage;
  render::RenderResult rendered = render::render(scene, options);
  const EnsembleSources sources =
      sourcesFromBuffers(std::move(rendered.buffers), readsHalves(ensemble.members()));
  run.render = stage.restart();
  const EnsembleResult result = ensemble.run(sources);
  for (const StageTime& t : result.times)
    if (t.stage == "bases") run.bases = t.seconds;
  run.combine = stage.restart() - run.bases;
  const std::vector<uint8_t> png = encodePng(result.combined.image);
  run.png = stage.restart();
  run.wall = total.seconds();
  run.cpu = processCpuSeconds() - cpu0;
  run.image = result.combined.image;
  run.noisy = result.guides.color;
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  chorus::reuseFreedMemory();
  CLI::App app("Preview latency and quality: render + preview ensemble, end to end");
  std::string scenePath = "scenes/cornell-box.gltf", preview = cli::kPreviewDenoise,
              full = cli::kDefaultDenoise, cache;
  int size = 512, spp = 4, threads = 2, repeat = 5, referenceSpp = 1024;
  int emissionSamples = render::RenderOptions{}.emissionSamples;
  app.add_option("--scene", scenePath, "glTF scene")->capture_default_str();
  app.add_option("--size", size, "Image width and height")->capture_default_str();
  app.add_option("--spp", spp, "Samples per pixel")->capture_default_str();
  app.add_option("--threads", threads, "TBB threads")->capture_default_str();
  app.add_option("--repeat", repeat, "Timed runs (best and median are printed)")
      ->capture_default_str();
  app.add_option("--preview", preview, "Preview members")->capture_default_str();
  app.add_option("--full", full, "Members of the full ensemble compared with")
      ->capture_default_str();
  app.add_option("--reference-spp", referenceSpp, "Reference samples per pixel")
      ->capture_default_str();
  app.add_option("--reference-cache", cache, "Directory to keep the reference render in");
  app.add_option("--emission-samples", emissionSamples,
                 "As chorus render's flag: emission-pass rays per pixel (0: not separated)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  tbb::global_control control(tbb::global_control::max_allowed_parallelism, size_t(threads));

  const Stopwatch load;
  const render::Scene scene = render::buildScene(render::loadGltf(scenePath), {});
  std::printf("scene %s loaded and built in %.3f s (not in the figures below)\n", scenePath.c_str(),
              load.seconds());
  render::RenderOptions options;
  options.width = options.height = size;
  options.spp = spp;
  options.threads = threads;
  options.setEmissionSamples(emissionSamples);
  CombineOptions previewOptions;
  cli::applyPreviewDefaults(previewOptions);  // as `chorus render --preview`
  const Ensemble ensemble(membersFromSpecs(splitMethodList(preview)), previewOptions);
  options.splits = splitsNeeded(ensemble.members());  // as `chorus render`

  runOnce(scene, options, ensemble);  // warm-up: page faults, TBB start-up, dispatch tables
  std::vector<Run> runs;
  for (int i = 0; i < repeat; ++i) runs.push_back(runOnce(scene, options, ensemble));
  std::sort(runs.begin(), runs.end(), [](const Run& a, const Run& b) { return a.wall < b.wall; });
  const Run& best = runs.front();
  const Run& median = runs[runs.size() / 2];
  std::printf("preview %s, %dx%d, %d spp, %d threads, %d runs:\n", preview.c_str(), size, size, spp,
              threads, repeat);
  std::printf("  %-7s %7s %7s %7s %7s %7s %9s\n", "", "wall s", "cpu s", "render", "bases",
              "combine", "png");
  for (const auto& [name, r] :
       {std::pair<const char*, const Run*>{"best", &best}, {"median", &median}})
    std::printf("  %-7s %7.3f %7.3f %7.3f %7.3f %7.3f %9.3f\n", name, r->wall, r->cpu, r->render,
                r->bases, r->combine, r->png);
  std::printf("  target: <= 1.0 s wall (best %s)\n", best.wall <= 1.0 ? "meets it" : "misses it");

  render::RenderOptions referenceOptions = options;
  referenceOptions.spp = referenceSpp;
  const Image reference = sweep::referenceRender(
      scene, referenceOptions,
      cache.empty() ? std::filesystem::path()
                    : std::filesystem::path(cache) / ("preview-" + std::to_string(size) + "-" +
                                                      std::to_string(referenceSpp) + "spp.exr"),
      "bench_preview");
  const Ensemble fullEnsemble(membersFromSpecs(splitMethodList(full)), {});
  render::RenderOptions fullOptions = options;
  fullOptions.splits = splitsNeeded(fullEnsemble.members());
  const Run fullRun = runOnce(scene, fullOptions, fullEnsemble);
  std::printf("relMSE against a %d-spp reference at %d spp:\n", referenceSpp, spp);
  std::printf("  noisy                    %.5f\n", relMse(best.noisy, reference));
  std::printf("  preview (%s)  %.5f  (%.3f s)\n", preview.c_str(), relMse(best.image, reference),
              best.wall);
  std::printf("  full (%s)  %.5f  (%.3f s)\n", full.c_str(), relMse(fullRun.image, reference),
              fullRun.wall);
  return 0;
}
