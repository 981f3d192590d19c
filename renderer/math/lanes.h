#pragma once
// Four floats side by side (one SSE register), for tracing four paths at once: GCC/Clang vector
// extensions, so +, −, ×, ÷ and comparisons work lane by lane. Every helper evaluates exactly
// what its scalar counterpart in vec.h and <algorithm> evaluates, in the same order, so lane
// results equal scalar results bit for bit (no FMA contraction: the portable target has none).
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include <cmath>
#include <cstdint>

#include "renderer/math/vec.h"

namespace chorus::render::lanes {

inline constexpr int kWidth = 4;
using Float = float __attribute__((vector_size(16)));
using Int = int32_t __attribute__((vector_size(16)));
using UInt = uint32_t __attribute__((vector_size(16)));  // for bit arithmetic that may wrap
using Mask = Int;  // −1 (true) or 0 in each lane, as comparisons produce

inline Float splat(float v) {
  return Float{v, v, v, v};
}
inline Float select(Mask m, Float a, Float b) {
  return m ? a : b;
}
inline Mask select(Mask m, Mask a, Mask b) {
  return m ? a : b;
}
// Bit i set where lane i is true.
inline int laneBits(Mask m) {
#if defined(__SSE__)
  return _mm_movemask_ps(__m128(m));
#else
  return (m[0] & 1) | (m[1] & 2) | (m[2] & 4) | (m[3] & 8);
#endif
}
inline bool any(Mask m) {
  return laneBits(m) != 0;
}
inline int count(Mask m) {
  return __builtin_popcount(unsigned(laneBits(m)));
}
inline Float abs(Float x) {
  return Float(Int(x) & 0x7fffffff);
}
inline Float sqrt(Float x) {
#if defined(__SSE__)
  return Float(_mm_sqrt_ps(__m128(x)));
#else
  return Float{std::sqrt(x[0]), std::sqrt(x[1]), std::sqrt(x[2]), std::sqrt(x[3])};
#endif
}
// std::min(a, b) and std::max(a, b): (b < a) ? b : a and (a < b) ? b : a (NaN and ±0 included).
inline Float min(Float a, Float b) {
  return select(b < a, b, a);
}
inline Float max(Float a, Float b) {
  return select(a < b, b, a);
}
// std::isfinite: x − x is 0 exactly for finite x and NaN for ±∞ and NaN.
inline Mask isFinite(Float x) {
  return (x - x) == splat(0.0f);
}

struct Vec3 {
  Float x, y, z;

  Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  Vec3 operator-() const { return {-x, -y, -z}; }
  Vec3 operator*(const Vec3& o) const { return {x * o.x, y * o.y, z * o.z}; }  // Rgb × Rgb
  Vec3 operator*(Float s) const { return {x * s, y * s, z * s}; }
  Vec3 operator/(Float s) const { return {x / s, y / s, z / s}; }

  // Lane i of each component from / into a scalar vector (also Rgb).
  void set(int i, Vec3f v) { x[i] = v.x, y[i] = v.y, z[i] = v.z; }
  void set(int i, Rgb c) { x[i] = c.r, y[i] = c.g, z[i] = c.b; }
  Vec3f at(int i) const { return {x[i], y[i], z[i]}; }
  Rgb rgbAt(int i) const { return {x[i], y[i], z[i]}; }
};

inline Vec3 select(Mask m, const Vec3& a, const Vec3& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}
inline Float dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Float length(const Vec3& v) {
  return sqrt(dot(v, v));
}
inline Vec3 abs(const Vec3& v) {
  return {abs(v.x), abs(v.y), abs(v.z)};
}
inline Float maxComponent(const Vec3& v) {
  return max(v.x, max(v.y, v.z));
}
inline Mask isBlack(const Vec3& c) {
  return (c.x == 0) & (c.y == 0) & (c.z == 0);
}
inline Mask isFinite(const Vec3& v) {
  return isFinite(v.x) & isFinite(v.y) & isFinite(v.z);
}

}  // namespace chorus::render::lanes
