#include "tools/sweep/reference_render.h"

#include <cstdio>

#include "common/atomic_file.h"
#include "common/image/exr_io.h"
#include "common/stopwatch.h"

namespace chorus::sweep {

Image referenceRender(const render::Scene& scene, render::RenderOptions options,
                      const std::filesystem::path& cacheFile, const std::string& log) {
  options.splits = 1;
  options.seed = kReferenceSeed;
  if (!cacheFile.empty() && std::filesystem::is_regular_file(cacheFile)) {
    Image cached = readExrLayer(cacheFile);
    // A cache written for another resolution is stale, not an error.
    if (options.width <= 0 || cached.width() == options.width) return cached;
  }
  const Stopwatch time;
  Image reference = render::render(scene, options).buffers.noisyColor();
  if (!log.empty())
    std::fprintf(stderr, "%s: reference %dx%d at %d spp in %.1f s\n", log.c_str(),
                 reference.width(), reference.height(), options.spp, time.seconds());
  if (!cacheFile.empty()) {
    ensureDirectory(cacheFile.parent_path());
    writeExr(cacheFile, reference);
  }
  return reference;
}

}  // namespace chorus::sweep
