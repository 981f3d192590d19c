#include "renderer/integrator/bsdf.h"

#include <algorithm>
#include <cmath>

#include "renderer/integrator/fresnel.h"
#include "renderer/sampling/warps.h"

namespace chorus::render {
namespace {

// A solid needs a relative IOR away from 1: at η = 1 every microfacet refracts straight through
// and the rough BTDF degenerates into a delta.
constexpr float kMinIor = 1.01f, kMaxIor = 4.0f;
// Below this the diffuse base receives no energy at all (a perfect mirror coating).
constexpr float kMinBaseEnergy = 1e-4f;
// Rough lobes whose weight estimate at the macro normal is 0 (black metal seen head-on, glass
// at total internal reflection) can still scatter through tilted microfacets: keep sampling them.
constexpr float kMinRoughLobeWeight = 0.05f;

float clamp01(float v) {
  return v >= 0 ? std::min(v, 1.0f) : 0.0f;  // also maps NaN to 0
}
Rgb clamp01(Rgb c) {
  return {clamp01(c.r), clamp01(c.g), clamp01(c.b)};
}
Vec3f mirrorZ(Vec3f v) {
  return {v.x, v.y, -v.z};
}
bool grazingSafe(Vec3f w) {
  return std::abs(w.z) >= kMinBsdfCosine && isFinite(w);
}
bool finiteDraws(float uLobe, Vec2f u) {
  return std::isfinite(uLobe) && std::isfinite(u.x) && std::isfinite(u.y);
}

// Smooth limit of the layer albedo terms: E = F(μ); its average 2∫ (1 − μ)^5 μ dμ = 1/21.
SpecularAlbedoTerms smoothLayerTerms(float cosTheta) {
  const float w = schlickWeight(cosTheta);
  return {1.0f - w, w};
}
constexpr SpecularAlbedoTerms kSmoothLayerAverage{20.0f / 21.0f, 1.0f / 21.0f};

}  // namespace

Bsdf::Bsdf(const MaterialPoint& material) : m_(material) {
  m_.baseColor = clamp01(material.baseColor);
  m_.metallic = clamp01(material.metallic);
  m_.roughness = clamp01(material.roughness);
  m_.transmission = clamp01(material.transmission);
  m_.specular = clamp01(material.specular);
  m_.specularColor = {std::max(0.0f, material.specularColor.r),
                      std::max(0.0f, material.specularColor.g),
                      std::max(0.0f, material.specularColor.b)};
  m_.ior = std::isfinite(material.ior) ? std::clamp(material.ior, kMinIor, kMaxIor) : 1.5f;
  eta_ = m_.ior;
  smooth_ = m_.roughness < kDeltaRoughness;
  ggx_ = GgxDistribution::fromRoughness(m_.roughness);
  transmits_ = (1.0f - m_.metallic) * m_.transmission > 0 && m_.baseColor.maxComponent() > 0;
  solidTransmission_ = !m_.thinWalled && transmits_;
  // specular = 0 removes the layer (and with metallic = 0 leaves a plain Lambertian, which then
  // skips all microfacet work).
  roughReflection_ = !smooth_ && (m_.metallic > 0 || m_.specular > 0);
  // A black one scatters nothing and takes the general path, which says so.
  lambertian_ =
      m_.metallic == 0 && m_.specular == 0 && m_.transmission == 0 && m_.baseColor.average() > 0;

  // KHR_materials_specular: f0 = min(f0(ior) · specularColor, 1) · specular, f90 = specular.
  const float f0Ior = f0FromIor(eta_);
  f0_ = {std::min(f0Ior * m_.specularColor.r, 1.0f), std::min(f0Ior * m_.specularColor.g, 1.0f),
         std::min(f0Ior * m_.specularColor.b, 1.0f)};
  f0Max_ = f0_.maxComponent();
  SpecularAlbedoTerms average = kSmoothLayerAverage;
  if (!smooth_ && m_.specular > 0) {
    layerAlbedoRow_ = SpecularAlbedoRow(m_.roughness);
    average = layerAlbedoRow_.average();
  }
  averageLayerAlbedo_ = m_.specular * average.albedo(f0Max_, 1.0f);
  const Rgb averageLayerAlbedoRgb =
      Rgb(average.albedo(f0_.r, 1.0f), average.albedo(f0_.g, 1.0f), average.albedo(f0_.b, 1.0f)) *
      m_.specular;

  const Rgb dielectricAlbedo = averageLayerAlbedoRgb + m_.baseColor * (1.0f - averageLayerAlbedo_);
  albedo_ = dielectricAlbedo * (1.0f - m_.metallic) + m_.baseColor * m_.metallic;
  const bool diffuse =
      (1.0f - m_.metallic) * (1.0f - m_.transmission) * m_.baseColor.maxComponent() > 0 &&
      1.0f - averageLayerAlbedo_ > kMinBaseEnergy;
  purelySpecular_ = smooth_ && !diffuse;
}

// Fresnel reflectance of the dielectric layer: Schlick at the cosine on the outer side, so
// that reflection and transmission agree from both sides of a solid; from inside beyond the
// critical angle everything the layer passes is reflected (*transmits = false).
Rgb Bsdf::dielectricFresnel(float cosTheta, bool inside, bool* transmits) const {
  const float cosOuter = inside ? outerCosine(cosTheta, 1.0f / eta_) : cosTheta;
  *transmits = cosOuter >= 0;
  if (!*transmits) return Rgb(m_.specular);
  return schlickFresnel(f0_, 1.0f, cosOuter) * m_.specular;
}

float Bsdf::layerAlbedo(float cosTheta) const {
  if (m_.specular == 0) return 0;
  const SpecularAlbedoTerms terms =
      smooth_ ? smoothLayerTerms(cosTheta) : layerAlbedoRow_.at(cosTheta);
  return std::min(1.0f, m_.specular * terms.albedo(f0Max_, 1.0f));
}

// Probability of reflecting (rather than transmitting) at a microfacet with Fresnel `fresnel`,
// proportional to the two weights the BSDF gives them.
float Bsdf::reflectTransmitChoice(const Rgb& fresnel, bool transmits) const {
  const float reflect = fresnel.average();
  const float transmit =
      transmits ? m_.transmission * m_.baseColor.average() * (1.0f - fresnel.maxComponent()) : 0;
  if (!(reflect + transmit > 0)) return 1.0f;
  return reflect / (reflect + transmit);
}

Bsdf::Outgoing Bsdf::prepare(Vec3f wo) const {
  Outgoing c;
  c.usable_ = grazingSafe(wo);
  if (!c.usable_) return c;
  c.flip_ = wo.z < 0;
  c.inside_ = c.flip_ && solidTransmission_;
  c.wo_ = c.flip_ ? mirrorZ(wo) : wo;
  if (lambertian_) {
    // What the general path below reduces to, without its Fresnel and layer-albedo terms.
    c.weights_.diffuse = 1.0f;
    return c;
  }
  if (!c.inside_) c.layerAlbedoO_ = layerAlbedo(c.wo_.z);
  if (roughReflection_ || (!smooth_ && transmits_)) c.lambdaO_ = ggx_.lambda(c.wo_);
  c.weights_ = lobeWeights(c);
  return c;
}

Bsdf::LobeWeights Bsdf::lobeWeights(const Outgoing& c) const {
  LobeWeights w;
  const float dielectric = 1.0f - m_.metallic;
  const float baseAverage = m_.baseColor.average();
  if (!c.inside_) {
    if (1.0f - averageLayerAlbedo_ > kMinBaseEnergy)
      w.diffuse = dielectric * (1.0f - m_.transmission) * baseAverage * (1.0f - c.layerAlbedoO_);
    w.metal = m_.metallic * schlickFresnel(m_.baseColor, 1.0f, c.wo_.z).average();
    if (!smooth_) w.metal = std::max(w.metal, m_.metallic * kMinRoughLobeWeight);
  }
  bool transmits;
  const Rgb fresnel = dielectricFresnel(c.wo_.z, c.inside_, &transmits);
  float transmit = transmits ? m_.transmission * baseAverage * (1.0f - fresnel.maxComponent()) : 0;
  if (!smooth_) transmit = std::max(transmit, m_.transmission * baseAverage * kMinRoughLobeWeight);
  w.interface = dielectric * (fresnel.average() + transmit);

  const float total = w.diffuse + w.metal + w.interface;
  if (!(total > 0)) return {};
  w.diffuse /= total;
  w.metal /= total;
  w.interface /= total;
  return w;
}

// Albedo-scaled Lambertian base (see bsdf.h): reciprocal, and ∫ f cos = ρ (1 − E(μo)).
Rgb Bsdf::diffuseF(float layerAlbedoO, float cosThetaI) const {
  const float baseEnergy = 1.0f - averageLayerAlbedo_;
  if (!(baseEnergy > kMinBaseEnergy)) return {};
  const float weight = (1.0f - m_.metallic) * (1.0f - m_.transmission);
  if (weight == 0) return {};
  if (m_.specular == 0) return m_.baseColor * (weight * kInvPi);  // exactly Lambertian
  const float scale =
      (1.0f - layerAlbedoO) * (1.0f - layerAlbedo(cosThetaI)) / baseEnergy * weight * kInvPi;
  return m_.baseColor * scale;
}

// f and pdf of the non-delta lobes for a canonical wo (c.wo_.z > 0) and wi in the same frame.
BsdfEval Bsdf::evalCanonical(const Outgoing& c, Vec3f wi) const {
  const Vec3f wo = c.wo_;
  const LobeWeights& w = c.weights_;
  const float dielectric = 1.0f - m_.metallic;
  BsdfEval e;
  if (wi.z > 0) {
    if (!c.inside_) {
      e.f += diffuseF(c.layerAlbedoO_, wi.z);
      e.pdf += w.diffuse * cosineHemispherePdfSolidAngle(wi.z);
    }
    if (!roughReflection_) return e;
    const Vec3f h = normalize(wo + wi);
    const float cosOH = dot(wo, h);
    const float D = ggx_.D(h);
    const float microfacet = D / ((1.0f + c.lambdaO_ + ggx_.lambda(wi)) * 4.0f * wo.z * wi.z);
    // Visible-normal pdf / (4 wo·h) = G1(wo) D / (4 wo.z) (Heitz 2018, eq. 17 with the
    // reflection Jacobian).
    const float reflectPdf = D / ((1.0f + c.lambdaO_) * 4.0f * wo.z);
    if (!c.inside_ && m_.metallic > 0) {
      e.f += schlickFresnel(m_.baseColor, 1.0f, cosOH) * (m_.metallic * microfacet);
      e.pdf += w.metal * reflectPdf;
    }
    if (dielectric > 0) {
      bool transmits;
      const Rgb fresnel = dielectricFresnel(cosOH, c.inside_, &transmits);
      e.f += fresnel * (dielectric * microfacet);
      e.pdf += w.interface * reflectTransmitChoice(fresnel, transmits) * reflectPdf;
    }
    return e;
  }
  if (smooth_ || !transmits_) return e;

  const float weight = dielectric * m_.transmission;
  if (!solidTransmission_) {
    // Thin-walled: the reflection lobe mirrored through the surface (no refraction).
    const Vec3f wr = mirrorZ(wi);
    const Vec3f h = normalize(wo + wr);
    bool transmits;
    const Rgb fresnel = dielectricFresnel(dot(wo, h), false, &transmits);
    const float D = ggx_.D(h);
    const float microfacet = D / ((1.0f + c.lambdaO_ + ggx_.lambda(wr)) * 4.0f * wo.z * wr.z);
    e.f = m_.baseColor * (weight * (1.0f - fresnel.maxComponent()) * microfacet);
    e.pdf = w.interface * (1.0f - reflectTransmitChoice(fresnel, transmits)) * D /
            ((1.0f + c.lambdaO_) * 4.0f * wo.z);
    return e;
  }
  // Walter et al. 2007, eq. 21, with the radiance scaling 1/η² (η = n_wi / n_wo):
  // f = |wi·h| |wo·h| / (|wi.z| wo.z) · D G (1 − F) / (wo·h + η wi·h)².
  const float eta = c.inside_ ? 1.0f / eta_ : eta_;
  const Vec3f halfway = wo + wi * eta;
  if (!(lengthSquared(halfway) > 1e-12f)) return e;
  const Vec3f h = faceForward(normalize(halfway), Vec3f(0, 0, 1));
  const float cosOH = dot(wo, h), cosIH = dot(wi, h);
  if (cosOH <= 0 || cosIH >= 0) return e;
  bool transmits;
  const Rgb fresnel = dielectricFresnel(cosOH, c.inside_, &transmits);
  if (!transmits) return e;
  const float denom = cosOH + eta * cosIH;
  const float D = ggx_.D(h);
  const float G = 1.0f / (1.0f + c.lambdaO_ + ggx_.lambda(wi));
  const float value = D * G * (-cosIH) * cosOH / (wo.z * -wi.z * denom * denom);
  e.f = m_.baseColor * (weight * (1.0f - fresnel.maxComponent()) * value);
  // Visible-normal pdf times dωh/dωi = η² |wi·h| / (wo·h + η wi·h)² (Walter et al. 2007, eq. 17).
  const float visibleNormalPdf = cosOH * D / ((1.0f + c.lambdaO_) * wo.z);
  const float jacobian = eta * eta * (-cosIH) / (denom * denom);
  e.pdf = w.interface * (1.0f - reflectTransmitChoice(fresnel, transmits)) * visibleNormalPdf *
          jacobian;
  return e;
}

BsdfEval Bsdf::evaluate(const Outgoing& c, Vec3f wi) const {
  if (!c.usable_ || !grazingSafe(wi)) return {};
  if (lambertian_) {
    // evalCanonical's diffuse term, reflection only (the lobe weight is 1, or 0 when black).
    if (c.flip_ != (wi.z < 0)) return {};
    return {m_.baseColor * kInvPi, cosineHemispherePdfSolidAngle(std::abs(wi.z))};
  }
  return evalCanonical(c, c.flip_ ? mirrorZ(wi) : wi);
}

Rgb Bsdf::f(Vec3f wo, Vec3f wi) const {
  return evaluate(wo, wi).f;
}

float Bsdf::pdf(Vec3f wo, Vec3f wi) const {
  return evaluate(wo, wi).pdf;
}

std::optional<BsdfSample> Bsdf::sample(const Outgoing& c, float uLobe, Vec2f u) const {
  if (!c.usable_ || !finiteDraws(uLobe, u)) return std::nullopt;
  if (lambertian_) {
    // The diffuse branch below, without the lobe choice and the general evaluation.
    const Vec3f wi = sampleCosineHemisphere(u);
    if (!grazingSafe(wi)) return std::nullopt;
    const float pdf = cosineHemispherePdfSolidAngle(wi.z);
    if (!(pdf > 0)) return std::nullopt;
    return BsdfSample{m_.baseColor * kInvPi, c.flip_ ? mirrorZ(wi) : wi, pdf, false, false};
  }
  const Vec3f wo = c.wo_;
  const LobeWeights& w = c.weights_;
  if (!w.any()) return std::nullopt;
  const auto finish = [&](BsdfSample s) -> std::optional<BsdfSample> {
    if (!(s.pdf > 0) || !s.f.isFinite() || !isFinite(s.wi)) return std::nullopt;
    s.isTransmission = s.wi.z < 0;
    if (c.flip_) s.wi = mirrorZ(s.wi);
    return s;
  };
  const auto nonDelta = [&](Vec3f wi) -> std::optional<BsdfSample> {
    if (!grazingSafe(wi)) return std::nullopt;
    const BsdfEval e = evalCanonical(c, wi);
    return finish({e.f, wi, e.pdf, false, false});
  };

  // Diffuse: cosine-weighted hemisphere.
  if (uLobe < w.diffuse || w.metal + w.interface == 0) return nonDelta(sampleCosineHemisphere(u));

  // Metal: GGX reflection sampled by visible normals, or a mirror.
  if (uLobe < w.diffuse + w.metal || w.interface == 0) {
    if (smooth_) {
      const Vec3f wi{-wo.x, -wo.y, wo.z};
      const Rgb fresnel = schlickFresnel(m_.baseColor, 1.0f, wo.z);
      return finish({fresnel * (m_.metallic / wo.z), wi, w.metal, true, false});
    }
    const Vec3f wi = reflect(wo, ggx_.sampleVisibleNormal(wo, u));
    if (wi.z <= 0) return std::nullopt;
    return nonDelta(wi);
  }

  // Dielectric interface: choose reflection or transmission at the microfacet in proportion to
  // their weights, reusing the remainder of uLobe.
  const float uChoice =
      std::clamp((uLobe - w.diffuse - w.metal) / w.interface, 0.0f, 0x1.fffffep-1f);
  const float dielectric = 1.0f - m_.metallic;
  const float eta = c.inside_ ? 1.0f / eta_ : eta_;
  const Vec3f h = smooth_ ? Vec3f(0, 0, 1) : ggx_.sampleVisibleNormal(wo, u);
  const float cosOH = dot(wo, h);
  bool transmits;
  const Rgb fresnel = dielectricFresnel(cosOH, c.inside_, &transmits);
  const float reflectChoice = reflectTransmitChoice(fresnel, transmits);
  const bool reflection = uChoice < reflectChoice;

  Vec3f wi;
  if (reflection) {
    wi = reflect(wo, h);
    if (wi.z <= 0) return std::nullopt;
  } else if (!solidTransmission_) {
    wi = mirrorZ(reflect(wo, h));
    if (wi.z >= 0) return std::nullopt;
  } else {
    if (!refract(wo, h, eta, &wi) || wi.z >= 0) return std::nullopt;
  }
  if (!smooth_) return nonDelta(wi);

  // Smooth: Dirac deltas, f carries 1 / |cos θi| (and 1/η² for refraction).
  const float lobePdf = w.interface * (reflection ? reflectChoice : 1.0f - reflectChoice);
  if (reflection) return finish({fresnel * (dielectric / wi.z), wi, lobePdf, true, false});
  const float transmittance = dielectric * m_.transmission * (1.0f - fresnel.maxComponent());
  const float radianceScale = solidTransmission_ ? 1.0f / (eta * eta) : 1.0f;
  return finish({m_.baseColor * (transmittance * radianceScale / -wi.z), wi, lobePdf, true, false});
}

}  // namespace chorus::render
