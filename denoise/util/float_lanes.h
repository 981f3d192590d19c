#pragma once
// Float1 / Float4: one float or four SSE2 lanes behind the same operators, so that a filter
// kernel written once as a template runs four pixels per instruction in the image interior
// and one at a time at the borders, performing the same float operations in the same order
// (bit-identical results whichever path computed a pixel). Without SSE2 only Float1 exists.
#include <cmath>

#include "denoise/util/fast_exp.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#include <xmmintrin.h>
#endif

namespace chorus {

// While alive, the calling thread flushes denormal results to zero and reads denormal inputs
// as zero (x86 MXCSR FTZ and DAZ; nothing elsewhere). Weights such as max(0, n·n')^128 or w²
// pass through the denormal range, where every operation would take a microcode assist
// costing ~100 cycles. Results stay deterministic (the same on every x86-64 CPU); the
// previous mode is restored on destruction.
class FlushDenormals {
 public:
#if defined(__SSE2__)
  FlushDenormals() : saved_(_mm_getcsr()) {
    _mm_setcsr(saved_ | 0x8040u);
  }
  ~FlushDenormals() {
    _mm_setcsr(saved_);
  }
#endif
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;

 private:
#if defined(__SSE2__)
  unsigned saved_;
#endif
};

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
// Correctly rounded, like sqrtps.
inline Float1 sqrt(Float1 a) {
  return {std::sqrt(a.v)};
}
// exp(−e), with fast_exp.h's polynomial of degree kDegree.
template <int kDegree = 6>
inline Float1 expNegated(Float1 e) {
  return {fastExpNonPositive<kDegree>(-e.v)};
}

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
inline Float4 sqrt(Float4 a) {
  return {_mm_sqrt_ps(a.v)};
}
template <int kDegree = 6>
inline Float4 expNegated(Float4 e) {
  return {fastExpNegatedSse<kDegree>(e.v)};
}

#endif

}  // namespace chorus
