#pragma once
// The environment as a light: constant radiance (sampled uniformly over the sphere) or an
// equirectangular map (importance-sampled by a 2D piecewise-constant distribution proportional
// to luminance × sin θ, so the solid-angle pdf follows the map; pbrt-v4 §12.5.3). Orientation
// as documented in renderer/scene/environment.h.
#include <optional>

#include "renderer/math/vec.h"
#include "renderer/sampling/distributions.h"
#include "renderer/scene/environment.h"

namespace chorus::render {

class EnvironmentLight {
 public:
  EnvironmentLight() = default;  // black
  explicit EnvironmentLight(const EnvironmentDesc& desc);

  // Whether it emits at all (a black map or colour emits nothing and is never sampled).
  bool emits() const { return emits_; }
  // Radiance arriving from world direction `direction` (unit).
  Rgb Le(const Vec3f& direction) const;

  struct Sample {
    Vec3f wi;  // unit, toward the environment
    Rgb Le;
    float pdfSolidAngle = 0;
  };
  std::optional<Sample> sample(Vec2f u) const;
  float pdfSolidAngle(const Vec3f& direction) const;

  // Le(direction) and, when asked for and Le is not black, pdfSolidAngle(direction), from one
  // mapping of the direction to the map (its acos and atan2 are most of a lookup's cost): a
  // path that escapes after a BSDF sample needs both for MIS.
  struct Arrival {
    Rgb Le;
    float pdfSolidAngle = 0;
  };
  Arrival arrival(const Vec3f& direction, bool withPdf) const;

  // Power estimate for choosing between lights: an emitter of the environment's mean radiance
  // on the scene's bounding sphere, 4π² r² L̄ (as pbrt-v4's infinite lights).
  float power(float sceneRadius) const;

 private:
  Vec3f toMap(Vec3f world) const;
  Vec3f toWorld(Vec3f map) const;
  Rgb texel(Vec2f uv) const;
  // pdfSolidAngle of map-space direction d, whose map position is uv.
  float mapPdf(Vec3f d, Vec2f uv) const;

  EnvironmentDesc::Kind kind_ = EnvironmentDesc::Kind::None;
  bool emits_ = false;
  Rgb constant_;
  std::shared_ptr<const Image> map_;  // linear RGB
  float scale_ = 1.0f;
  float cosRotation_ = 1.0f, sinRotation_ = 0.0f;
  PiecewiseConstant2D distribution_;
  float meanLuminance_ = 0.0f;
};

}  // namespace chorus::render
