#pragma once
// Fresnel terms of the glTF material model (glTF 2.0 Appendix B; KHR_materials_specular, _ior).
#include <algorithm>
#include <cmath>

#include "renderer/math/vec.h"

namespace chorus::render {

// Schlick's approximation with normal-incidence reflectance f0 and grazing reflectance f90.
inline float schlickWeight(float cosTheta) {
  const float m = std::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  const float m2 = m * m;
  return m2 * m2 * m;
}
inline Rgb schlickFresnel(Rgb f0, float f90, float cosTheta) {
  const float w = schlickWeight(cosTheta);
  return f0 * (1.0f - w) + Rgb(f90 * w);
}

// Normal-incidence reflectance of a dielectric of relative IOR `ior` against air.
inline float f0FromIor(float ior) {
  const float r = (ior - 1.0f) / (ior + 1.0f);
  return r * r;
}

// Cosine on the outer (lower-IOR) side for a dielectric interface seen at cosine `cosTheta`
// from a side where eta = IOR across / IOR here. On the outer side (eta >= 1) it is cosTheta;
// from inside (eta < 1) it is the cosine of the refracted ray, and −1 signals total internal
// reflection. Evaluating Schlick at the outer cosine makes R and T agree from both sides.
inline float outerCosine(float cosTheta, float eta) {
  if (eta >= 1.0f) return cosTheta;
  const float sin2Outer = (1.0f - cosTheta * cosTheta) / (eta * eta);
  if (sin2Outer >= 1.0f) return -1.0f;
  return std::sqrt(1.0f - sin2Outer);
}

}  // namespace chorus::render
