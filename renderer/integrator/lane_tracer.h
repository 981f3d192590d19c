#pragma once
// Four paths at a time, one per SIMD lane, for scenes made only of plain Lambertian surfaces
// with flat triangles lit by untextured area lights (Cornell boxes and other diffuse interiors).
// Each lane renders one pixel's samples in order and takes the tile's next pixel when they are
// done; the four rays of a step go to Embree as one packet, and the shading, light sampling and
// MIS of PathTracer::trace for that case run on all four lanes at once. The lane arithmetic
// repeats the scalar tracer's operations in their order, so images are bit-identical to it.
#include <cstdint>
#include <optional>
#include <vector>

#include "renderer/integrator/camera.h"
#include "renderer/integrator/film.h"
#include "renderer/integrator/lights.h"
#include "renderer/integrator/path_tracer.h"

namespace chorus::render {

class LaneTileRenderer;

class LaneTracer {
 public:
  // A tracer for the scene, or nothing when anything in it needs the general tracer (textures,
  // specular layers, metal, transmission, alpha, vertex normals that vary over a triangle,
  // punctual lights, an environment).
  static std::optional<LaneTracer> create(const Scene& scene, const LightSet& lights,
                                          PathTracerSettings settings);

  struct Tile {
    int x0, y0, x1, y1;
  };
  struct Sampling {
    int spp, splits;
    uint64_t seed;
  };
  // Renders the tile's pixels into `film`, as the scalar loop of render() would; adds the rays
  // traced and the non-finite samples dropped.
  void renderTile(const Tile& tile, const Sampling& sampling, const Camera& camera, Film& film,
                  PathTracer::RayCounts& rays, uint64_t& dropped) const;

  // What a hit on a material needs, per material index.
  struct Surface {
    Rgb albedo;    // Bsdf::albedo()
    Rgb f;         // the Lambertian BSDF value, baseColor / π
    Rgb emission;  // emitted radiance (0 when not emissive)
    bool doubleSided;
  };

 private:
  LaneTracer(const Scene& scene, const LightSet& lights, PathTracerSettings settings)
      : scene_(&scene), lights_(&lights), settings_(settings) {}

  friend class LaneTileRenderer;
  const Scene* scene_;
  const LightSet* lights_;
  PathTracerSettings settings_;
  std::vector<Surface> surfaces_;
};

}  // namespace chorus::render
