#pragma once
// The isotropic GGX (Trowbridge–Reitz) microfacet distribution with the height-correlated Smith
// masking-shadowing function, sampled by visible normals (Heitz 2018, "Sampling the GGX
// distribution of visible normals"). Local frame: z is the macro-surface normal.
#include "renderer/math/vec.h"

namespace chorus::render {

class GgxDistribution {
 public:
  // alpha = perceptual roughness², clamped away from 0 for numerical stability.
  explicit GgxDistribution(float alpha);
  static GgxDistribution fromRoughness(float roughness) {
    return GgxDistribution(roughness * roughness);
  }

  float alpha() const { return alpha_; }

  // D(h): density of microfacet normals with respect to solid angle, projected: ∫ D(h) h.z = 1.
  float D(Vec3f h) const;
  // Smith Λ(w) (Heitz 2014, eq. 72): Λ = (−1 + sqrt(1 + α² tan²θ)) / 2.
  float lambda(Vec3f w) const;
  float G1(Vec3f w) const { return 1.0f / (1.0f + lambda(w)); }
  // Height-correlated masking-shadowing G2 = 1 / (1 + Λ(wo) + Λ(wi)) (Heitz 2014, eq. 99).
  float G(Vec3f wo, Vec3f wi) const { return 1.0f / (1.0f + lambda(wo) + lambda(wi)); }

  // Visible normal density seen from w (w.z > 0): D_w(h) = G1(w) max(0, w·h) D(h) / w.z.
  float visibleNormalPdf(Vec3f w, Vec3f h) const;
  // A microfacet normal (h.z > 0) distributed by D_w, for w.z > 0.
  Vec3f sampleVisibleNormal(Vec3f w, Vec2f u) const;

 private:
  float alpha_;
};

// Mirror w about the normal h.
inline Vec3f reflect(Vec3f w, Vec3f h) {
  return h * (2.0f * dot(w, h)) - w;
}

// Refraction of w (pointing away from the surface, w·h > 0) through a boundary with normal h,
// where eta = IOR on the far side / IOR on w's side. Returns false on total internal reflection.
inline bool refract(Vec3f w, Vec3f h, float eta, Vec3f* wt) {
  const float cosI = dot(w, h);
  const float sin2T = std::max(0.0f, 1.0f - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0f) return false;
  const float cosT = std::sqrt(1.0f - sin2T);
  *wt = -w / eta + h * (cosI / eta - cosT);
  return true;
}

}  // namespace chorus::render
