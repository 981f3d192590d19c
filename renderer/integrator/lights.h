#pragma once
// All the scene's lights behind one sampling interface: emissive triangles (area lights),
// KHR_lights_punctual point/spot/directional lights and the environment. One light is chosen per
// next-event estimate from an alias table proportional to each light's estimated power, so a
// bright small emitter gets more samples than a dim large one. Only the structures the scene
// needs are built (no alias entries without lights, no environment distribution without a map).
#include <optional>
#include <vector>

#include "renderer/integrator/environment_light.h"
#include "renderer/sampling/distributions.h"
#include "renderer/scene/scene.h"

namespace chorus::render {

struct LightSample {
  Rgb Li;         // radiance arriving along −wi (for delta lights, the delta's weight: I/d², E)
  Vec3f wi;       // unit direction from the shading point toward the light
  float pdf = 0;  // solid-angle pdf × choice probability; delta lights: the choice probability
  bool isDelta = false;
  bool isInfinite = false;  // environment or directional: no end point
  // End point of the shadow ray (finite lights), its rounding bound and the light's normal
  // (zero for point and spot lights).
  Vec3f pLight, pLightError, nLight;
};

class LightSet {
 public:
  explicit LightSet(const Scene& scene);

  bool empty() const { return lights_.empty(); }

  struct AreaLight {
    uint32_t geomID = 0, primID = 0;
    float area = 0;
    Vec3f p0, p1, p2;  // world-space corners
    // Set when the whole triangle has one oriented normal and one emission (flat or no vertex
    // normals, untextured emission), which is then kept here: no scene lookups per sample.
    bool uniform = false;
    bool doubleSided = false;
    Vec3f normal;
    Rgb Le;
  };
  // The light uChoice selects (alias table by power) and its probability; `uniformArea` is set
  // when it is a uniform area light, whose sampling the lane tracer repeats in SIMD lanes.
  struct Pick {
    int index = 0;
    float pmf = 0;
    const AreaLight* uniformArea = nullptr;
  };
  Pick pick(float uChoice) const;

  // Picks a light with uChoice and a point or direction on it with u (nothing where the pick's
  // probability is 0 or the sample carries no light).
  std::optional<LightSample> sample(const Vec3f& refPosition, float uChoice, Vec2f u) const {
    return sample(refPosition, pick(uChoice), u);
  }
  std::optional<LightSample> sample(const Vec3f& refPosition, const Pick& pick, Vec2f u) const;

  // The pdf sample() would have for reaching emissive triangle `lightPoint` from refPosition
  // (solid angle, including the choice probability): the MIS weight of a BSDF-sampled hit.
  float pdfAreaLight(const Vec3f& refPosition, const SurfaceInteraction& lightPoint) const;
  // What a ray escaping in direction `direction` (unit) receives from the environment, and
  // when withPdf, likewise the pdf of sampling that direction (0 where the radiance is black).
  EnvironmentLight::Arrival environmentArrival(const Vec3f& direction, bool withPdf) const;

  size_t areaLightCount() const { return areaLights_.size(); }

 private:
  enum class Kind : uint8_t { Area, Punctual, Environment };
  struct LightRef {
    Kind kind;
    uint32_t index;  // into areaLights_ or the scene's punctual lights
  };

  // Fill `s` (default-constructed) and return true, or return false when no sample results.
  bool sampleArea(const AreaLight& light, const Vec3f& ref, Vec2f u, LightSample& s) const;
  bool samplePunctual(const PunctualLightDesc& light, const Vec3f& ref, LightSample& s) const;

  const Scene* scene_;
  std::vector<AreaLight> areaLights_;  // index = SceneMesh::firstAreaLight + primID
  std::vector<LightRef> lights_;       // area lights first, so lights_[i] for i < #area is area i
  AliasTable choice_;
  EnvironmentLight environment_;
  int environmentIndex_ = -1;  // in lights_
};

// Veach's power heuristic (β = 2) for the strategy with pdf a against one with pdf b.
inline float powerHeuristic(float a, float b) {
  const float a2 = a * a, b2 = b * b;
  if (!(a2 + b2 > 0)) return 0.0f;
  if (std::isinf(a2)) return 1.0f;
  return a2 / (a2 + b2);
}

}  // namespace chorus::render
