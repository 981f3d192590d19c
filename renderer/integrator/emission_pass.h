#pragma once
// The emission pass of a render that separates emission (RenderOptions::separateEmission): the
// film's emission plane holds, per pixel, the mean of what its samples saw emitted directly or in
// mirrors, which is exact when they all saw the same. Where they differ (the edge of a light, a
// defocused light, a sky's texture), and next to such pixels (an edge that the few samples all
// missed), it is estimated again with many camera paths of its own that stop at the first
// surface that is not a mirror: a camera ray and the mirror bounces each, no light samples, so
// it costs little beside the paths.
#include <cstdint>
#include <vector>

#include "renderer/integrator/camera.h"
#include "renderer/integrator/film.h"
#include "renderer/integrator/path_tracer.h"

namespace chorus::render {

// The sampler stream of the emission pass: after the sub-buffers', so its draws are
// independent of theirs.
inline constexpr int kEmissionStream = kMaxSplits;

// Pixels (y · width + x) whose samples saw different emission, and their eight neighbours, in
// increasing order.
std::vector<uint32_t> emissionPassPixels(const Film& film);

// Adds `samples` emission-only paths (non-finite ones left out) to the path samples' own at each
// of `pixels`: film.emission() becomes the mean of both; adds the rays traced to `rays`. Runs on
// the calling task arena.
void runEmissionPass(Film& film, const std::vector<uint32_t>& pixels, const PathTracer& tracer,
                     const Camera& camera, uint64_t seed, int samples, PathTracer::RayCounts& rays);

}  // namespace chorus::render
