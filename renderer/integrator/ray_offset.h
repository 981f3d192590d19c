#pragma once
// Self-intersection-free ray origins in single precision, relative to the scene's own scale
// (scenes range from centimetres to hundreds of units, so no fixed epsilon works).
//
// A hit point computed from barycentrics, p = b0 p0 + b1 p1 + b2 p2, lies within
// γ₇ (|b0 p0| + |b1 p1| + |b2 p2|) of the exact point on the triangle per axis (pbrt-v4 §6.8.5,
// γₙ = nε/(1 − nε), ε = 2⁻²⁴). Moving the origin along the geometric normal by that bound's
// projection, then one more float step away from the surface, puts it strictly on the side of
// the outgoing direction, so the new ray cannot re-hit the surface it left and cannot start on
// the far side of it (no leaks).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "renderer/math/vec.h"

namespace chorus::render {

inline constexpr float kMachineEpsilon = std::numeric_limits<float>::epsilon() * 0.5f;
constexpr float roundingGamma(int n) {
  return (float(n) * kMachineEpsilon) / (1 - float(n) * kMachineEpsilon);
}

// Safety factor on the bound: it also absorbs the rounding of Embree's barycentrics.
inline constexpr float kOffsetSafety = 4.0f;

inline Vec3f barycentricPositionError(Vec3f p0, Vec3f p1, Vec3f p2, float b0, float b1, float b2) {
  return (abs(p0 * b0) + abs(p1 * b1) + abs(p2 * b2)) * (roundingGamma(7) * kOffsetSafety);
}

// The next representable float above / below v (finite v; ±0 step to the smallest subnormal).
inline float nextFloatUp(float v) {
  if (v == 0.0f) return std::numeric_limits<float>::denorm_min();
  uint32_t bits = std::bit_cast<uint32_t>(v);
  bits = v > 0 ? bits + 1 : bits - 1;
  return std::bit_cast<float>(bits);
}
inline float nextFloatDown(float v) {
  return -nextFloatUp(-v);
}

// Smallest offset, for points whose rounding bound is 0 (all vertices at coordinate 0).
inline constexpr float kMinOffset = 1e-9f;

// The origin for a ray leaving point p (with error bound pError) in direction w; n is the
// geometric normal (either orientation). The bound is used isotropically (its largest
// component): an axis without rounding error (a plane at y = 0) still gets moved off the
// surface, since Embree would report the plane again at t = 0.
inline Vec3f offsetRayOrigin(Vec3f p, Vec3f pError, Vec3f n, Vec3f w) {
  const float e = std::max(maxComponent(pError), kMinOffset);
  const float d = e * (std::abs(n.x) + std::abs(n.y) + std::abs(n.z));
  Vec3f offset = n * d;
  if (dot(w, n) < 0) offset = -offset;
  Vec3f po = p + offset;
  // Round away from p so that the offset survives the addition's rounding.
  for (int i = 0; i < 3; ++i) {
    if (offset[i] > 0)
      po[i] = nextFloatUp(po[i]);
    else if (offset[i] < 0)
      po[i] = nextFloatDown(po[i]);
  }
  return po;
}

// Shadow rays end slightly before their target point (pbrt's ShadowEpsilon), in units of the
// unnormalised direction target − origin.
inline constexpr float kShadowEpsilon = 1e-4f;

}  // namespace chorus::render
