#pragma once
// Warps from [0,1)² to sampling domains, each next to its pdf (with the measure in the name).
#include "renderer/math/vec.h"

namespace chorus::render {

Vec3f sampleCosineHemisphere(Vec2f u);  // local frame, z up
inline float cosineHemispherePdfSolidAngle(float cosTheta) {
  return cosTheta > 0 ? cosTheta * kInvPi : 0.0f;
}

Vec3f sampleUniformSphere(Vec2f u);
inline constexpr float kUniformSpherePdfSolidAngle = 1.0f / (4.0f * kPi);

// Barycentrics (b0, b1) of a uniformly distributed point on a triangle (b2 = 1 − b0 − b1).
Vec2f sampleUniformTriangle(Vec2f u);

// Uniform direction in the cone of half-angle acos(cosThetaMax) around +z.
Vec3f sampleUniformCone(Vec2f u, float cosThetaMax);
inline float uniformConePdfSolidAngle(float cosThetaMax) {
  return 1.0f / (2.0f * kPi * (1.0f - cosThetaMax));
}

// Equal-area mapping between [0,1)² and the unit disk (Shirley–Chiu concentric).
Vec2f sampleConcentricDisk(Vec2f u);

// sin and cos of |x| ≤ π/4 by their Taylor series to x⁹ and x¹⁰ (truncation below 2·10⁻⁹,
// under float rounding): a BSDF sample's sincosf call was 2 % of the render's instructions.
// `Real` is float, or four floats in SIMD lanes (renderer/math/lanes.h) with equal results.
template <typename Real>
struct SinCos {
  Real sin, cos;
};
template <typename Real>
SinCos<Real> sinCosQuarterPi(Real x) {
  constexpr float kSin[] = {1.0f, -1.0f / 6, 1.0f / 120, -1.0f / 5040, 1.0f / 362880};
  constexpr float kCos[] = {1.0f, -1.0f / 2, 1.0f / 24, -1.0f / 720, 1.0f / 40320, -1.0f / 3628800};
  const Real x2 = x * x;
  Real s = Real{} + kSin[4], c = Real{} + kCos[5];  // Horner's rule in x²
  for (int i = 3; i >= 0; --i) s = kSin[i] + x2 * s;
  for (int i = 4; i >= 0; --i) c = kCos[i] + x2 * c;
  return {x * s, c};
}

}  // namespace chorus::render
