#pragma once
// PathTracer::trace for four paths at a time, one per SIMD lane. Each lane renders one pixel's
// samples in order and takes the tile's next pixel when they are done; the four rays of a step
// go to Embree as one packet (closest hits, then shadow rays). Hits on flat triangles of plain
// Lambertian materials, uniform area lights, the Lambertian BSDF, MIS and roulette are computed
// on all four lanes at once; other surfaces (textured, layered, metal, glass), smooth triangles
// and other lights are handled one lane at a time with the one-path tracer's own functions. The
// lane arithmetic repeats the one-path tracer's operations in their order, so the images are
// bit-identical to it.
#include <cstdint>
#include <vector>

#include "renderer/integrator/camera.h"
#include "renderer/integrator/film.h"
#include "renderer/integrator/lights.h"
#include "renderer/integrator/path_tracer.h"

namespace chorus::render {

class LaneTileRenderer;

class LaneTracer {
 public:
  LaneTracer(const Scene& scene, const LightSet& lights, PathTracerSettings settings);

  struct Tile {
    int x0, y0, x1, y1;
  };
  struct Sampling {
    int spp, splits;
    uint64_t seed;
  };
  // The share of the scene's surface area whose BSDF and emission no texture varies, and the
  // share from which the lanes pay. Measured on 2026-12-04 (256², 32 spp, best of 3): where it is
  // 1 the lanes render 1.3x (the Cornell box, plain Lambertian) and 1.11x (CornellBox-Bevy, every
  // surface under a specular layer) as fast as one path at a time; on scenes mostly of textured
  // materials, where texture lookups and Bsdf set-up take each lane's time and the packets save
  // little, 0.90-1.02x (TransmissionTest, LightsPunctualLamp, FlightHelmet, punctual-lights).
  float untexturedAreaShare() const { return untexturedAreaShare_; }
  static constexpr float kWorthwhileAreaShare = 0.5f;

  // Renders the tile's pixels into `film`, as the one-path loop of render() would; adds the
  // rays traced and the non-finite samples dropped.
  void renderTile(const Tile& tile, const Sampling& sampling, const Camera& camera, Film& film,
                  PathTracer::RayCounts& rays, uint64_t& dropped) const;

 private:
  friend class LaneTileRenderer;

  // Per material index: whether no texture varies its BSDF and emission, whether its hits are
  // shaded in lanes (such a material that is plain Lambertian or black), and then what they need.
  struct Surface {
    bool untextured = false;
    bool inLanes = false;
    Rgb albedo;    // Bsdf::albedo()
    Rgb f;         // the Lambertian BSDF value, baseColor / π (0 for black)
    Rgb emission;  // emitted radiance (0 when not emissive)
    bool doubleSided = false;
  };

  const Scene* scene_;
  const LightSet* lights_;
  PathTracerSettings settings_;
  std::vector<Surface> surfaces_;
  float untexturedAreaShare_ = 0;
};

}  // namespace chorus::render
