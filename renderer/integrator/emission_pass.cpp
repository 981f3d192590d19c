#include "renderer/integrator/emission_pass.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "renderer/sampling/sampler.h"

namespace chorus::render {

std::vector<uint32_t> emissionPassPixels(const Film& film) {
  const int width = film.width(), height = film.height();
  std::vector<uint8_t> near(size_t(width) * size_t(height), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      if (!film.emittedVaries(x, y)) continue;
      for (int yy = std::max(0, y - 1); yy <= std::min(height - 1, y + 1); ++yy)
        for (int xx = std::max(0, x - 1); xx <= std::min(width - 1, x + 1); ++xx)
          near[size_t(yy) * size_t(width) + size_t(xx)] = 1;
    }
  std::vector<uint32_t> pixels;
  for (size_t i = 0; i < near.size(); ++i)
    if (near[i]) pixels.push_back(uint32_t(i));
  return pixels;
}

namespace {

// The sum of `samples` emission-only paths through pixel (x, y) and how many were finite.
struct EmissionSum {
  double sum[3] = {0, 0, 0};
  int kept = 0;
};
EmissionSum traceEmissions(int x, int y, int samples, const PathTracer& tracer,
                           const Camera& camera, Sampler& sampler, PathTracer::RayCounts& rays) {
  EmissionSum s;
  for (int i = 0; i < samples; ++i) {
    const Ray ray = startCameraSample(sampler, camera, x, y, uint32_t(i), kEmissionStream);
    const Rgb e = tracer.traceEmission(ray, sampler, rays);
    if (!std::isfinite(double(e.r) + double(e.g) + double(e.b))) continue;
    s.sum[0] += e.r, s.sum[1] += e.g, s.sum[2] += e.b;
    ++s.kept;
  }
  return s;
}

}  // namespace

void runEmissionPass(Film& film, const std::vector<uint32_t>& pixels, const PathTracer& tracer,
                     const Camera& camera, uint64_t seed, int samples,
                     PathTracer::RayCounts& rays) {
  std::atomic<uint64_t> closestHit{0};
  const uint32_t width = uint32_t(film.width());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels.size(), 64),
                    [&](const tbb::blocked_range<size_t>& range) {
                      Sampler sampler(seed);
                      PathTracer::RayCounts local;
                      for (size_t p = range.begin(); p < range.end(); ++p) {
                        const int x = int(pixels[p] % width), y = int(pixels[p] / width);
                        const EmissionSum pass =
                            traceEmissions(x, y, samples, tracer, camera, sampler, local);
                        // Pooled with the path samples' own (the plane holds their mean): the
                        // pass adds to what a high sample count already resolves.
                        const double n = film.samplesKept(x, y), total = n + pass.kept;
                        float* out = film.emission().pixel(x, y);
                        for (int c = 0; c < 3; ++c)
                          out[c] = total > 0 ? float((out[c] * n + pass.sum[c]) / total) : 0.0f;
                      }
                      closestHit += local.closestHit;
                    });
  rays.closestHit += closestHit;
}

}  // namespace chorus::render
