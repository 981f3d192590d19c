#pragma once
// High-spp reference renders for sweeps and benchmarks, cached as EXR files so that reruns
// reuse them (a 16k-spp reference can take longer than the whole rest of a sweep).
#include <filesystem>
#include <string>

#include "common/image/image.h"
#include "renderer/render.h"

namespace chorus::sweep {

// A seed for reference renders, far from the seeds of the renders they judge (so the reference
// noise is independent of theirs).
inline constexpr uint64_t kReferenceSeed = 1000;

// The full-buffer colour of `scene` rendered with `options` (K = 1, seed kReferenceSeed), read
// from `cacheFile` when it exists (and has the expected size), else rendered and written there
// atomically. An empty cacheFile disables the cache. `log` names the caller in the line it
// prints to stderr after rendering ("" prints nothing).
Image referenceRender(const render::Scene& scene, render::RenderOptions options,
                      const std::filesystem::path& cacheFile, const std::string& log);

}  // namespace chorus::sweep
