#pragma once
// The glTF 2.0 reference material model as a BSDF (glTF spec, Appendix B, plus the
// KHR_materials_transmission / _ior / _specular / _volume extensions):
//   - dielectric: Lambertian diffuse (baseColor) under a GGX specular layer with Fresnel
//     (ior, specular / specularColor), or, with `transmission`, a rough dielectric BTDF;
//   - metal: GGX reflection with Schlick Fresnel on baseColor;
//   mixed by `metallic`. GGX is sampled by visible normals (Heitz 2018).
//
// Conventions (pbrt-v4 style):
//   - All directions are in the local shading frame: z is the shading normal, pointing to the
//     side the surface faces (its outside). wo and wi point away from the surface.
//   - wo.z < 0 means the path arrives from inside: only meaningful for transmissive materials
//     (the relative IOR is inverted). For opaque materials the integrator flips the frame so
//     that wo.z > 0 before calling.
//   - f() does NOT include the cosine |wi.z|.
//   - Transmission carries radiance: f includes the 1/η² scaling of radiance crossing the
//     boundary (η = relative IOR of the side wi is on over the side wo is on).
//   - Roughness below kDeltaRoughness is treated as perfectly smooth: its lobes are Dirac
//     deltas, f() and pdf() return 0 for them and only sample() produces them (isDelta = true).
//     For a delta sample, f·|wi.z| / pdf is the path throughput weight, exactly as for other
//     samples (f carries the 1/|wi.z| of the delta, as in pbrt).
//   - sample() of a non-delta lobe returns the value and pdf of all non-delta lobes together
//     for that direction (equal to f(wo, wi) and pdf(wo, wi)), so MIS weights use pdf().
//
// Layering (see docs/renderer.md, BSDF): the diffuse base receives exactly the energy the GGX
// specular layer does not reflect, via albedo scaling with the layer's directional albedo E(μ):
//   f_diffuse = baseColor/π · (1 − E(μo)) (1 − E(μi)) / (1 − E_avg),
// which is reciprocal and keeps ∫ f cos ≤ 1 (the spec's per-half-vector (1 − F) weighting is
// not white-furnace-safe at grazing angles). specular = 0 gives exactly baseColor/π.
#include <optional>

#include "renderer/integrator/microfacet.h"
#include "renderer/integrator/specular_albedo.h"
#include "renderer/math/vec.h"

namespace chorus::render {

inline constexpr float kDeltaRoughness = 1e-3f;  // perceptual roughness
// Directions closer to the tangent plane than this scatter nothing: the microfacet terms'
// 1 / (cos θo cos θi) would underflow to 0 / 0.
inline constexpr float kMinBsdfCosine = 1e-7f;

// The material at one surface point, after texture lookups (all colours linear).
struct MaterialPoint {
  Rgb baseColor{1.0f};
  float metallic = 1.0f;    // glTF default
  float roughness = 1.0f;   // perceptual roughness; GGX alpha = roughness²
  float ior = 1.5f;         // KHR_materials_ior
  float transmission = 0;   // KHR_materials_transmission (fraction of the dielectric part)
  float specular = 1.0f;    // KHR_materials_specular specularFactor (0 → pure Lambertian)
  Rgb specularColor{1.0f};  // KHR_materials_specular specularColorFactor (linear)
  // Transmission without KHR_materials_volume is thin-walled per the glTF spec: light passes
  // straight through (no refraction, no interior). With a volume, the surface bounds a solid.
  bool thinWalled = true;
};

struct BsdfSample {
  Rgb f;          // BSDF value (without cosine); for delta lobes the delta's weight
  Vec3f wi;       // local frame
  float pdf = 0;  // solid-angle pdf; for delta lobes the discrete lobe probability
  bool isDelta = false;
  bool isTransmission = false;  // wi is on the other side of the surface than wo
};

// f and pdf for one pair of directions, computed together (cheaper than f() then pdf()).
struct BsdfEval {
  Rgb f;
  float pdf = 0;
};

class Bsdf {
  // Probabilities of choosing each lobe family in sample(); they sum to 1 (or are all 0 when the
  // material scatters nothing from this direction).
  struct LobeWeights {
    float diffuse = 0, metal = 0, interface = 0;
    bool any() const { return diffuse + metal + interface > 0; }
  };

 public:
  explicit Bsdf(const MaterialPoint& material);

  // What every evaluation and sample for one wo shares (the lobe weights, the layer albedo and
  // Smith Λ at wo): a path vertex prepares it once for its light sample and its BSDF sample.
  class Outgoing {
    friend class Bsdf;
    bool usable_ = false;  // not grazing (else nothing is scattered)
    // wo in the canonical frame (wo.z > 0); flip_ says it was mirrored, inside_ that the path
    // is inside a solid.
    Vec3f wo_;
    bool flip_ = false, inside_ = false;
    float layerAlbedoO_ = 0;
    float lambdaO_ = 0;
    LobeWeights weights_;
  };
  Outgoing prepare(Vec3f wo) const;

  Rgb f(Vec3f wo, Vec3f wi) const;
  BsdfEval evaluate(Vec3f wo, Vec3f wi) const { return evaluate(prepare(wo), wi); }
  BsdfEval evaluate(const Outgoing& o, Vec3f wi) const;  // {f(wo, wi), pdf(wo, wi)}
  // uLobe picks the lobe, u samples its direction. Returns nullopt when no direction results
  // (e.g. a microfacet normal that reflects below the surface).
  std::optional<BsdfSample> sample(Vec3f wo, float uLobe, Vec2f u) const {
    return sample(prepare(wo), uLobe, u);
  }
  std::optional<BsdfSample> sample(const Outgoing& o, float uLobe, Vec2f u) const;
  float pdf(Vec3f wo, Vec3f wi) const;

  // Every lobe is a delta (smooth glass, smooth metal): features are taken further down the
  // path, at the first vertex where this is false.
  bool isPurelySpecular() const { return purelySpecular_; }
  // Transmits light at all (so the integrator keeps transmission paths and shadow rays
  // pass thin-walled surfaces only where this is true).
  bool hasTransmission() const { return transmits_; }
  // Only a non-black Lambertian lobe: f = baseColor / π, sampled by the cosine.
  bool isPlainLambertian() const { return lambertian_; }
  // Black and without any specular lobe (e.g. the body of a light): f = 0 everywhere.
  bool scattersNothing() const {
    return m_.metallic == 0 && m_.specular == 0 && m_.transmission == 0 &&
           m_.baseColor.maxComponent() == 0;
  }
  // The value recorded in the albedo feature buffer: the material's overall reflectance colour
  // (baseColor for diffuse and metals, weighted by the lobe mix).
  Rgb albedo() const { return albedo_; }

 private:
  LobeWeights lobeWeights(const Outgoing& c) const;
  Rgb dielectricFresnel(float cosTheta, bool inside, bool* transmits) const;
  float layerAlbedo(float cosTheta) const;  // E(μ) of the specular layer, max over channels
  Rgb diffuseF(float layerAlbedoO, float cosThetaI) const;
  BsdfEval evalCanonical(const Outgoing& c, Vec3f wi) const;
  float reflectTransmitChoice(const Rgb& fresnel, bool transmits) const;

  MaterialPoint m_;  // clamped to valid ranges
  GgxDistribution ggx_{1.0f};
  SpecularAlbedoRow layerAlbedoRow_;  // rough with a specular layer only
  bool smooth_ = false;
  bool roughReflection_ = false;    // a rough metal or specular-layer lobe exists
  bool lambertian_ = false;         // only a non-black diffuse lobe, nothing layered on it
  bool purelySpecular_ = false;     // isPurelySpecular()
  bool transmits_ = false;          // hasTransmission()
  bool solidTransmission_ = false;  // refracts into a closed volume (wo.z < 0 is inside)
  float eta_ = 1.5f;                // IOR used by the interface (clamped away from 1)
  Rgb f0_;                          // dielectric normal reflectance per channel, before specular
  float f0Max_ = 0;
  float averageLayerAlbedo_ = 0;  // E_avg, max over channels
  Rgb albedo_;                    // albedo()
};

}  // namespace chorus::render
