#pragma once
// Float1 / Float4: one float or four SSE2 lanes behind the same operators, so that a filter
// kernel written once as a template runs four pixels per instruction in the image interior
// and one at a time at the borders, performing the same float operations in the same order
// (bit-identical results whichever path computed a pixel). Without SSE2 only Float1 exists.
#include <cmath>

#include "denoise/util/fast_exp.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace chorus {

struct Float1 {
  static constexpr int kWidth = 1;
  float v;
  static Float1 load(const float* p) { return {*p}; }
  static Float1 broadcast(float x) { return {x}; }
  void store(float* p) const { *p = v; }
};
inline Float1 operator+(Float1 a, Float1 b) {
  return {a.v + b.v};
}
inline Float1 operator-(Float1 a, Float1 b) {
  return {a.v - b.v};
}
inline Float1 operator*(Float1 a, Float1 b) {
  return {a.v * b.v};
}
inline Float1 operator/(Float1 a, Float1 b) {
  return {a.v / b.v};
}
inline Float1 abs(Float1 a) {
  return {std::abs(a.v)};
}
// max(0, a), with maxps semantics (NaN and ±0 give +0).
inline Float1 max0(Float1 a) {
  return {a.v > 0.0f ? a.v : 0.0f};
}
inline Float1 expNegated(Float1 e) {
  return {fastExpNonPositive(-e.v)};
}  // exp(−e)

#if defined(__SSE2__)
struct Float4 {
  static constexpr int kWidth = 4;
  __m128 v;
  static Float4 load(const float* p) { return {_mm_loadu_ps(p)}; }
  static Float4 broadcast(float x) { return {_mm_set1_ps(x)}; }
  void store(float* p) const { _mm_storeu_ps(p, v); }
};
inline Float4 operator+(Float4 a, Float4 b) {
  return {_mm_add_ps(a.v, b.v)};
}
inline Float4 operator-(Float4 a, Float4 b) {
  return {_mm_sub_ps(a.v, b.v)};
}
inline Float4 operator*(Float4 a, Float4 b) {
  return {_mm_mul_ps(a.v, b.v)};
}
inline Float4 operator/(Float4 a, Float4 b) {
  return {_mm_div_ps(a.v, b.v)};
}
// Clearing the sign bit, as std::abs does.
inline Float4 abs(Float4 a) {
  return {_mm_and_ps(a.v, _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff)))};
}
inline Float4 max0(Float4 a) {
  return {_mm_max_ps(a.v, _mm_setzero_ps())};
}
inline Float4 expNegated(Float4 e) {
  return {fastExpNegatedSse(e.v)};
}

// Eight lanes as two independent Float4: each operation issues two independent instructions,
// which hides the latency of long dependency chains (the exponential's polynomial).
struct Float4x2 {
  static constexpr int kWidth = 8;
  Float4 a, b;
  static Float4x2 load(const float* p) { return {Float4::load(p), Float4::load(p + 4)}; }
  static Float4x2 broadcast(float x) { return {Float4::broadcast(x), Float4::broadcast(x)}; }
  void store(float* p) const {
    a.store(p);
    b.store(p + 4);
  }
};
inline Float4x2 operator+(Float4x2 x, Float4x2 y) {
  return {x.a + y.a, x.b + y.b};
}
inline Float4x2 operator-(Float4x2 x, Float4x2 y) {
  return {x.a - y.a, x.b - y.b};
}
inline Float4x2 operator*(Float4x2 x, Float4x2 y) {
  return {x.a * y.a, x.b * y.b};
}
inline Float4x2 operator/(Float4x2 x, Float4x2 y) {
  return {x.a / y.a, x.b / y.b};
}
inline Float4x2 abs(Float4x2 x) {
  return {abs(x.a), abs(x.b)};
}
inline Float4x2 max0(Float4x2 x) {
  return {max0(x.a), max0(x.b)};
}
inline Float4x2 expNegated(Float4x2 e) {
  return {expNegated(e.a), expNegated(e.b)};
}
#endif

}  // namespace chorus
