#include "renderer/sampling/warps.h"

#include <cmath>

namespace chorus::render {

namespace {

// sin and cos of |x| ≤ π/4 by their Taylor series to x⁹ and x¹⁰ (truncation below 2·10⁻⁹,
// under float rounding): a BSDF sample's sincosf call was 2 % of the render's instructions.
struct SinCos {
  float sin, cos;
};
SinCos sinCosQuarterPi(float x) {
  constexpr float kSin[] = {1.0f, -1.0f / 6, 1.0f / 120, -1.0f / 5040, 1.0f / 362880};
  constexpr float kCos[] = {1.0f, -1.0f / 2, 1.0f / 24, -1.0f / 720, 1.0f / 40320, -1.0f / 3628800};
  const float x2 = x * x;
  float s = kSin[4], c = kCos[5];  // Horner's rule in x²
  for (int i = 3; i >= 0; --i) s = kSin[i] + x2 * s;
  for (int i = 4; i >= 0; --i) c = kCos[i] + x2 * c;
  return {x * s, c};
}

}  // namespace

Vec2f sampleConcentricDisk(Vec2f u) {
  // Shirley & Chiu 1997: map squares to wedges so that areas are preserved. The wedge angle is
  // θ = (π/4)(oy/ox), or π/2 − (π/4)(ox/oy), whose cosine and sine are those of (π/4)(ox/oy)
  // swapped: both need sin and cos on [−π/4, π/4] only.
  const float ox = 2.0f * u.x - 1.0f, oy = 2.0f * u.y - 1.0f;
  if (ox == 0 && oy == 0) return {0, 0};
  if (std::abs(ox) > std::abs(oy)) {
    const SinCos t = sinCosQuarterPi((kPi / 4.0f) * (oy / ox));
    return {ox * t.cos, ox * t.sin};
  }
  const SinCos t = sinCosQuarterPi((kPi / 4.0f) * (ox / oy));
  return {oy * t.sin, oy * t.cos};
}

Vec3f sampleCosineHemisphere(Vec2f u) {
  // Malley's method: project a uniform disk sample up onto the hemisphere.
  const Vec2f d = sampleConcentricDisk(u);
  const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}

Vec3f sampleUniformSphere(Vec2f u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

Vec2f sampleUniformTriangle(Vec2f u) {
  // Heitz 2019, "A low-distortion map between triangle and square".
  float b0, b1;
  if (u.x < u.y) {
    b0 = u.x / 2.0f;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2.0f;
    b0 = u.x - b1;
  }
  return {b0, b1};
}

Vec3f sampleUniformCone(Vec2f u, float cosThetaMax) {
  const float cosTheta = (1.0f - u.x) + u.x * cosThetaMax;
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  const float phi = u.y * 2.0f * kPi;
  return {std::cos(phi) * sinTheta, std::sin(phi) * sinTheta, cosTheta};
}

}  // namespace chorus::render
