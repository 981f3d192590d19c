#pragma once
// exp(x) for x ≤ 0, fast and vectorised: the filters' inner loops evaluate one exponential per
// pixel pair. Relative error below 1e-6 for x ∈ [−10, 0] and 5e-6 down to −87 (the default
// degree 6; degree 4 adds 3.5e-6 and saves two multiply-adds); results that
// would fall below about 2^−126 and NaN inputs give exactly 0; positive inputs are clamped to 0
// (result 1). The array form uses SSE2 four lanes at a time and the scalar form for the rest,
// fastExpNegatedVector any GCC vector type; all perform the same float operations in the same
// order, so every element is bit-identical whichever path computed it (determinism for any
// tiling).
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace chorus {

namespace fast_exp_detail {
// exp(x) = 2^t, t = x log2(e) = n + f, n = round(t) (via the 1.5·2^23 rounding trick, exact
// for |t| ≤ 2^22), f ∈ [−0.5, 0.5]; 2^f = e^y, y = f ln2, |y| ≤ 0.347, by a polynomial in y.
inline constexpr float kLog2e = 1.44269504f, kLn2 = 0.693147181f, kRound = 12582912.0f;
// The polynomial's coefficients, highest degree first. Degree 6: the Taylor series (remainder
// < 1.2e-7). Degree 4: the interpolant at the five Chebyshev nodes of [−ln2/2, ln2/2] (relative
// error 3.5e-6, evaluated in float), enough for filter weights.
template <int kDegree>
inline constexpr std::array<float, kDegree + 1> kExpPolynomial{};
template <>
inline constexpr std::array<float, 7> kExpPolynomial<6> = {
    1.0f / 720.0f, 1.0f / 120.0f, 1.0f / 24.0f, 1.0f / 6.0f, 0.5f, 1.0f, 1.0f};
template <>
inline constexpr std::array<float, 5> kExpPolynomial<4> = {0.0418756455f, 0.167921424f,
                                                           0.499993712f, 0.99996227f, 1.0f};
}  // namespace fast_exp_detail

template <int kDegree = 6>
inline float fastExpNonPositive(float x) {
  using namespace fast_exp_detail;
  float t = x * kLog2e;
  t = t > -127.0f ? t : -127.0f;  // also maps NaN to the floor (result 0)
  t = t < 0.0f ? t : 0.0f;
  const float rounded = t + kRound;
  const float n = rounded - kRound;
  // Biased exponent n + 127 from the low mantissa bits; 0 (t ≤ −126.5) gives +0 below.
  const int32_t biased = std::bit_cast<int32_t>(rounded) - std::bit_cast<int32_t>(kRound) + 127;
  const float y = (t - n) * kLn2;
  float p = kExpPolynomial<kDegree>[0];
  for (int i = 1; i <= kDegree; ++i) p = p * y + kExpPolynomial<kDegree>[size_t(i)];
  return p * std::bit_cast<float>(biased << 23);
}

// fastExpNonPositive<kDegree>(−e) in every lane of a GCC vector of floats V (I: the int32
// vector of the same lane count): the same float operations in the same order, hence the same
// bits in each lane, as vector code of any width (a loop over lanes calling the scalar form does
// not vectorise: its selects need no-trapping-math). Through references: a vector returned by
// value changes the ABI of the clones built without that width.
template <typename V, typename I, int kDegree = 6>
[[gnu::always_inline]] inline void fastExpNegatedVector(const V& e, V& out) {
  using namespace fast_exp_detail;
  const V zero{};
  V t = -e * kLog2e;
  t = t > -127.0f ? t : zero - 127.0f;  // NaN compares false: the floor, as in the scalar form
  t = t < 0.0f ? t : zero;
  const V rounded = t + kRound;
  const V n = rounded - kRound;
  const I biased = (I)rounded - std::bit_cast<int32_t>(kRound) + 127;
  const V y = (t - n) * kLn2;
  constexpr auto& poly = kExpPolynomial<kDegree>;
  V p = zero + poly[0];
  for (size_t i = 1; i < poly.size(); ++i) p = p * y + poly[i];
  out = p * (V)(biased << 23);
}

#if defined(__SSE2__)
// Four lanes of exp(−e), bit-identical to fastExpNonPositive<kDegree>(−e) in each lane.
template <int kDegree = 6>
inline __m128 fastExpNegatedSse(__m128 e) {
  using namespace fast_exp_detail;
  // −e·log2(e) equals (−e)·log2(e) exactly (sign symmetry), as in the scalar form.
  __m128 t = _mm_mul_ps(e, _mm_set1_ps(-kLog2e));
  t = _mm_max_ps(t, _mm_set1_ps(-127.0f));  // maxps returns the second operand for NaN
  t = _mm_min_ps(t, _mm_setzero_ps());
  const __m128 round = _mm_set1_ps(kRound);
  const __m128 rounded = _mm_add_ps(t, round);
  const __m128 n = _mm_sub_ps(rounded, round);
  const __m128i biased = _mm_add_epi32(_mm_castps_si128(rounded),
                                       _mm_set1_epi32(127 - std::bit_cast<int32_t>(kRound)));
  const __m128 y = _mm_mul_ps(_mm_sub_ps(t, n), _mm_set1_ps(kLn2));
  __m128 p = _mm_set1_ps(kExpPolynomial<kDegree>[0]);
  for (int k = 1; k <= kDegree; ++k)
    p = _mm_add_ps(_mm_mul_ps(p, y), _mm_set1_ps(kExpPolynomial<kDegree>[size_t(k)]));
  return _mm_mul_ps(p, _mm_castsi128_ps(_mm_slli_epi32(biased, 23)));
}
#endif

// out[i] = exp(−e[i]) for i < count (e ≥ 0; see above for other inputs). out may alias e.
inline void fastExpNegated(const float* e, float* out, int count) {
  int i = 0;
#if defined(__SSE2__)
  for (; i + 4 <= count; i += 4) _mm_storeu_ps(out + i, fastExpNegatedSse(_mm_loadu_ps(e + i)));
#endif
  for (; i < count; ++i) out[i] = fastExpNonPositive(-e[i]);
}

}  // namespace chorus
