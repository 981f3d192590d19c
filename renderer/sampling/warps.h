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

}  // namespace chorus::render
