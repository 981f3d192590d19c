#include "renderer/render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <mutex>
#include <string>

#include "common/error.h"
#include "common/stopwatch.h"
#include "common/thread_limit.h"
#include "renderer/integrator/camera.h"
#include "renderer/integrator/emission_pass.h"
#include "renderer/integrator/film.h"
#include "renderer/integrator/lane_tracer.h"
#include "renderer/integrator/lights.h"
#include "renderer/integrator/path_tracer.h"
#include "renderer/sampling/sampler.h"

namespace chorus::render {
namespace {

constexpr int kTileSize = 16;

void validate(const RenderOptions& o) {
  if (o.spp < 1) throw Error("--spp must be at least 1 (got " + std::to_string(o.spp) + ")");
  if (o.splits != 1 && o.splits != 2 && o.splits != 4)
    throw Error("--splits must be 1, 2 or 4 (got " + std::to_string(o.splits) + ")");
  if (o.width < 0 || o.height < 0) throw Error("--width and --height must be positive");
  if (o.maxDepth < 1) throw Error("--max-depth must be at least 1");
  checkThreadCount(o.threads);
  if (o.camera < 0) throw Error("--camera must be 0 or more");
  if (o.rouletteStartDepth < 0) throw Error("--roulette-depth must be 0 or more");
  if (!(o.lensRadius >= 0) || !std::isfinite(o.lensRadius))
    throw Error("--lens-radius must be a finite number >= 0");
  if (!(o.focusDistance >= 0) || !std::isfinite(o.focusDistance))
    throw Error("--focus-distance must be a finite number >= 0");
  if (o.emissionSamples < 1)
    throw Error("--emission-samples must be at least 1 (got " + std::to_string(o.emissionSamples) +
                ")");
}

}  // namespace

Resolution renderResolution(const Scene& scene, const RenderOptions& options) {
  // The camera's own aspect decides a missing dimension; the framing camera adapts to the image.
  const std::vector<CameraDesc>& cameras = scene.data().cameras;
  const CameraDesc* fileCamera = options.camera >= 0 && size_t(options.camera) < cameras.size()
                                     ? &cameras[size_t(options.camera)]
                                     : nullptr;
  return chooseResolution(fileCamera ? *fileCamera : CameraDesc{}, options.width, options.height);
}

CameraDesc focusCamera(const Scene& scene, const RenderOptions& options) {
  const Resolution resolution = renderResolution(scene, options);
  CameraDesc desc =
      selectCamera(scene, options.camera, float(resolution.width) / float(resolution.height));
  desc.lensRadius = options.lensRadius;
  desc.focusDistance = options.focusDistance;
  if (desc.lensRadius > 0 && desc.focusDistance == 0) {
    // Autofocus: the depth along the axis of what the centre pixel's pinhole ray sees.
    CameraDesc pinhole = desc;
    pinhole.lensRadius = 0;
    const Ray centre =
        Camera(pinhole, resolution)
            .generateRay({0.5f * float(resolution.width), 0.5f * float(resolution.height)});
    Hit hit;
    const float depth = scene.intersect(centre, &hit)
                            ? hit.t * dot(centre.direction, desc.forward)
                            : dot(scene.bounds().center() - desc.position, desc.forward);
    if (!(depth > 0) || !std::isfinite(depth))
      throw Error("cannot autofocus: nothing in front of the camera; give --focus-distance");
    desc.focusDistance = depth;
  }
  // The camera's own checks (a lens on an orthographic camera), naming the scene.
  try {
    Camera(desc, resolution);
  } catch (const Error& e) {
    throw fileError(scene.data().source, e.what());
  }
  return desc;
}

RenderResult render(const Scene& scene, const RenderOptions& options,
                    const ProgressCallback& progress) {
  validate(options);
  const Stopwatch elapsed;

  const Resolution resolution = renderResolution(scene, options);
  const CameraDesc cameraDesc = focusCamera(scene, options);
  const Camera camera(cameraDesc, resolution);
  const LightSet lights(scene);
  const PathTracerSettings settings{options.maxDepth, options.rouletteStartDepth};
  const PathTracer tracer(scene, lights, settings);
  std::optional<LaneTracer> laneTracer;
  if (options.tracer != RenderOptions::Tracer::OnePath) {
    laneTracer.emplace(scene, lights, settings);
    if (options.tracer == RenderOptions::Tracer::Automatic &&
        laneTracer->untexturedAreaShare() < LaneTracer::kWorthwhileAreaShare)
      laneTracer.reset();
  }
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  Film film = arena.execute([&] {
    return Film(resolution.width, resolution.height, options.splits, options.planes,
                options.separateEmission);
  });

  const int tilesX = (resolution.width + kTileSize - 1) / kTileSize;
  const int tilesY = (resolution.height + kTileSize - 1) / kTileSize;
  const uint64_t samplesTotal =
      uint64_t(resolution.width) * uint64_t(resolution.height) * uint64_t(options.spp);
  std::atomic<uint64_t> rays{0}, shadowRays{0}, dropped{0}, samplesDone{0};
  std::mutex progressMutex;

  const auto renderTile = [&](int tile) {
    const int x0 = (tile % tilesX) * kTileSize, y0 = (tile / tilesX) * kTileSize;
    const int x1 = std::min(x0 + kTileSize, resolution.width);
    const int y1 = std::min(y0 + kTileSize, resolution.height);
    PathTracer::RayCounts tileRays;
    uint64_t tileDropped = 0;
    if (laneTracer) {
      laneTracer->renderTile({x0, y0, x1, y1}, {options.spp, options.splits, options.seed}, camera,
                             film, tileRays, tileDropped);
    } else {
      Sampler sampler(options.seed);
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          PixelAccumulator pixel(film.separatesEmission());
          for (int i = 0; i < options.spp; ++i) {
            const Ray ray = startPixelSample(sampler, camera, x, y, i, options.splits);
            if (!pixel.add(i % options.splits, tracer.trace(ray, sampler, tileRays))) ++tileDropped;
          }
          film.store(x, y, pixel);
        }
      }
    }
    rays += tileRays.closestHit + tileRays.shadow;
    shadowRays += tileRays.shadow;
    dropped += tileDropped;
    const uint64_t done = samplesDone +=
        uint64_t(x1 - x0) * uint64_t(y1 - y0) * uint64_t(options.spp);
    if (progress) {
      const std::lock_guard<std::mutex> lock(progressMutex);
      progress({done, samplesTotal, elapsed.seconds()});
    }
  };

  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, tilesX * tilesY, 1),
        [&](const tbb::blocked_range<int>& range) {
          for (int tile = range.begin(); tile < range.end(); ++tile) renderTile(tile);
        },
        tbb::simple_partitioner());
  });

  RenderResult result;
  RenderStats& s = result.stats;
  if (options.separateEmission) {
    const Stopwatch pass;
    const std::vector<uint32_t> pixels = emissionPassPixels(film);
    PathTracer::RayCounts passRays;
    arena.execute([&] {
      runEmissionPass(film, pixels, tracer, camera, options.seed, options.emissionSamples,
                      passRays);
    });
    rays += passRays.closestHit;
    s.emissionPixels = pixels.size();
    s.emissionSeconds = pass.seconds();
  }
  result.buffers = film.release();
  s.width = resolution.width;
  s.height = resolution.height;
  s.spp = options.spp;
  s.splits = options.splits;
  s.renderSeconds = elapsed.seconds();
  s.samples = samplesTotal;
  s.rays = rays;
  s.shadowRays = shadowRays;
  s.nanSamplesDropped = dropped;
  s.triangles = scene.data().triangleCount;
  s.lanes = laneTracer.has_value();
  s.focusDistance = camera.thinLens() ? cameraDesc.focusDistance : 0.0f;
  return result;
}

}  // namespace chorus::render
