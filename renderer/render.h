#pragma once
// The renderer's in-process entry point: a built Scene + options → SampleBuffers (K independent
// sub-buffers of colour and features with their variances) and statistics.
//
//   SceneDesc desc = loadGltf("scene.gltf");                        // renderer/scene/gltf_loader.h
//   Scene scene = buildScene(std::move(desc), EnvironmentDesc{});    // renderer/scene/scene.h
//   RenderOptions options;  options.spp = 64;  options.splits = 4;
//   RenderResult result = render(scene, options);
//   result.buffers.input(BufferPart::HalfA) ...                      // denoise/buffers
//
// A Scene can be rendered any number of times (e.g. a sweep over spp); render() only reads it.
// Determinism: the same scene, options.seed, spp, splits, resolution and camera give
// bit-identical buffers for any thread count (each pixel is computed by one task, its samples in
// order; sample i of a pixel goes to sub-buffer i mod K and uses that sub-buffer's own scramble).
#include <cstdint>
#include <functional>

#include "denoise/buffers/sample_buffers.h"
#include "renderer/integrator/camera.h"
#include "renderer/scene/scene.h"

namespace chorus::render {

struct RenderOptions {
  int width = 0, height = 0;  // 0: from the camera (see chooseResolution in camera.h)
  int spp = 64;               // samples per pixel, over all sub-buffers
  int splits = 1;             // K ∈ {1, 2, 4}
  uint64_t seed = 0;
  int threads = 0;   // 0: all cores
  int maxDepth = 8;  // maximum number of scattering events per path
  // Russian roulette from this bounce on (a value above maxDepth turns it off, e.g. to compare
  // with renderers that trace every path to full length).
  int rouletteStartDepth = 3;
  int camera = 0;  // index into the scene's cameras (0 with none: frame the bounds)
  // Depth of field (glTF cameras have none): the thin lens's radius in world units (0: a
  // pinhole) and the distance along the view axis that is in focus (0: autofocus, the distance
  // to the surface under the image centre; see focusCamera).
  float lensRadius = 0, focusDistance = 0;
  // Which path tracer renders (the images are bit-identical; only the speed differs):
  // Automatic takes LaneTracer (four paths in SIMD lanes) when at least half the scene's surface
  // area has a material no texture varies, else PathTracer one path at a time.
  enum class Tracer { Automatic, Lanes, OnePath };
  Tracer tracer = Tracer::Automatic;
  // The planes the sub-buffers record (colour always): what the denoisers will read. The planes
  // kept are bit-identical whatever the others are.
  BufferPlanes planes = BufferPlanes::all();
  // Emission seen directly or in mirrors (PathSample::emitted; not through glass) is taken out
  // of every sample's colour and kept in SampleBuffers::emission(): the denoisers then filter
  // only the light reflected by what the camera sees, and a small lamp's radiance cannot spread
  // over its neighbours. Where a pixel's samples saw different emission (the edge of a light, a
  // defocused light, a sky's texture), and next to such pixels, that plane is estimated again
  // from emissionSamples more camera paths followed only as far as their first surface that is
  // not a mirror (emission_pass.h): edges of lights are then resolved as well as at that many
  // samples per pixel, at the cost of a camera ray each.
  bool separateEmission = false;
  int emissionSamples = 64;
  // What `--emission-samples N` means: separated with N pass samples, or not at all for N = 0.
  void setEmissionSamples(int samples) {
    separateEmission = samples > 0;
    if (samples > 0) emissionSamples = samples;
  }
};

struct RenderStats {
  int width = 0, height = 0, spp = 0, splits = 0;
  double renderSeconds = 0;
  uint64_t samples = 0;            // paths traced (width × height × spp)
  uint64_t rays = 0;               // camera, bounce and shadow rays
  uint64_t shadowRays = 0;         // of which shadow rays
  uint64_t nanSamplesDropped = 0;  // samples with a non-finite value, not accumulated
  size_t triangles = 0;
  bool lanes = false;  // traced by LaneTracer (four paths in SIMD lanes), else by PathTracer
  uint64_t emissionPixels = 0;  // pixels the emission pass estimated again (separateEmission)
  double emissionSeconds = 0;   // that pass's time (included in renderSeconds)
  float focusDistance = 0;      // the thin lens's, autofocus resolved (0: a pinhole)
  double samplesPerSecond() const {
    return renderSeconds > 0 ? double(samples) / renderSeconds : 0;
  }
  double raysPerSecond() const { return renderSeconds > 0 ? double(rays) / renderSeconds : 0; }
};

struct RenderProgress {
  uint64_t samplesDone = 0, samplesTotal = 0;
  double elapsedSeconds = 0;
  double fraction() const { return samplesTotal ? double(samplesDone) / double(samplesTotal) : 1; }
};
// Called from worker threads, one call at a time, after each finished tile.
using ProgressCallback = std::function<void(const RenderProgress&)>;

struct RenderResult {
  SampleBuffers buffers;
  RenderStats stats;
};

// The image size render() gives `options` on `scene` (the width and height given, the rest from
// the camera's aspect), for checks before rendering: memory, the size of a reference.
Resolution renderResolution(const Scene& scene, const RenderOptions& options);

// The camera render() uses: the scene's camera `options.camera` with the options' lens. With a
// lens and focusDistance 0 it focuses on the surface under the image centre (along the axis),
// or on the scene bounds' centre when that ray hits nothing.
CameraDesc focusCamera(const Scene& scene, const RenderOptions& options);

// Throws chorus::Error for invalid options (spp < 1, splits not 1/2/4, a missing camera, …).
RenderResult render(const Scene& scene, const RenderOptions& options,
                    const ProgressCallback& progress = {});

}  // namespace chorus::render
