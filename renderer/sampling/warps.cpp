#include "renderer/sampling/warps.h"

#include <cmath>

namespace chorus::render {

Vec2f sampleConcentricDisk(Vec2f u) {
  // Shirley & Chiu 1997: map squares to wedges so that areas are preserved. The wedge angle is
  // θ = (π/4)(oy/ox), or π/2 − (π/4)(ox/oy), whose cosine and sine are those of (π/4)(ox/oy)
  // swapped: both need sin and cos on [−π/4, π/4] only.
  const float ox = 2.0f * u.x - 1.0f, oy = 2.0f * u.y - 1.0f;
  if (ox == 0 && oy == 0) return {0, 0};
  if (std::abs(ox) > std::abs(oy)) {
    const auto t = sinCosQuarterPi((kPi / 4.0f) * (oy / ox));
    return {ox * t.cos, ox * t.sin};
  }
  const auto t = sinCosQuarterPi((kPi / 4.0f) * (ox / oy));
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
