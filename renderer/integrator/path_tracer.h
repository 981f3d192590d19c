#pragma once
// Unidirectional path tracing with next-event estimation. Area lights and the environment are
// reached both by light sampling and by BSDF sampling, combined with the power heuristic
// (Veach 1997, §9.2); punctual lights only by light sampling. Russian roulette from the third
// bounce on, with the survival probability min(1, max throughput component) (radiance scaling
// by refraction factored out). Shadow rays are blocked by every surface except alpha-test
// cutouts: light through glass is found by BSDF sampling only.
//
// Features (recorded per sample, at the first vertex whose BSDF is not purely specular, so
// mirror and glass chains are followed):
//   albedo      Bsdf::albedo() times the throughput of the specular chain before the vertex
//   normal      world-space shading normal, turned to face the incoming ray
//   depth       distance travelled along the path from the camera to the vertex
//   visibility  1 if the vertex's next-event estimate found its light unoccluded with a non-zero
//               contribution, else 0 (the pixel mean is the fraction of unoccluded shadow rays)
//   emitted     (not a feature) the part of the radiance emitted by what the camera sees
//               directly or through mirrors: lights and the environment reached before that
//               vertex or a glass one, and the own emission of the first such vertex
//               (renderer/render.h's separateEmission takes it out of the colour the
//               denoisers filter)
// Rays that escape before such a vertex: albedo = the chain's throughput (1 for camera rays:
// white, so dividing by albedo leaves the background unchanged), normal = 0, depth = 0,
// visibility = 1. Paths that end inside a specular chain (absorbed, roulette, maximum depth)
// keep the last specular vertex's albedo, normal and depth, with visibility 0.
//
// LaneTracer (lane_tracer.h) repeats trace() for four paths at a time, operation for operation:
// a change here must be made there too (lane_tracer_test compares the two bit for bit).
#include <cstdint>

#include "renderer/integrator/camera.h"
#include "renderer/integrator/film.h"
#include "renderer/integrator/lights.h"
#include "renderer/sampling/sampler.h"
#include "renderer/scene/scene.h"

namespace chorus::render {

struct PathTracerSettings {
  int maxDepth = 8;            // maximum number of scattering events on a path
  int rouletteStartDepth = 3;  // Russian roulette from this bounce on
};

// Starts sample `sample` of pixel (x, y) — sub-buffer sample mod splits, index sample / splits
// in it — and returns its camera ray through the position in the pixel drawn first.
Ray startPixelSample(Sampler& sampler, const Camera& camera, int x, int y, int sample, int splits);
// The same for sample `index` of the sampler's stream `stream` (a sub-buffer, or another
// independent set of draws such as the emission pass's).
Ray startCameraSample(Sampler& sampler, const Camera& camera, int x, int y, uint32_t index,
                      int stream);

// Beer–Lambert transmittance through `distance` of a KHR_materials_volume interior:
// σ = −ln(attenuationColor) / attenuationDistance.
Rgb volumeTransmittance(const MaterialDesc& m, float distance);

class PathTracer {
 public:
  PathTracer(const Scene& scene, const LightSet& lights, PathTracerSettings settings)
      : scene_(scene), lights_(lights), settings_(settings) {}

  // Rays traced, by kind (Embree's closest-hit and occlusion queries differ in cost).
  struct RayCounts {
    uint64_t closestHit = 0;  // camera and bounce rays
    uint64_t shadow = 0;      // next-event visibility
  };

  // One path from a camera ray. Consumes sampler dimensions in the order documented in
  // renderer/sampling/sampler.h; adds the rays it traces to `rays`.
  PathSample trace(const Ray& cameraRay, Sampler& sampler, RayCounts& rays) const;
  // PathSample::emitted of a path from this camera ray, traced only as far as that needs (the
  // first vertex that is not purely specular; no light samples), with the same draws.
  Rgb traceEmission(const Ray& cameraRay, Sampler& sampler, RayCounts& rays) const;

 private:
  PathSample trace(const Ray& cameraRay, Sampler& sampler, RayCounts& rays,
                   bool emissionOnly) const;
  bool unoccluded(const SurfaceInteraction& si, const Vec3f& ng, const LightSample& light) const;

  const Scene& scene_;
  const LightSet& lights_;
  PathTracerSettings settings_;
};

}  // namespace chorus::render
