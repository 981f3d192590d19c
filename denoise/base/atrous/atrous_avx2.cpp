// The à-trous level kernel (atrous_kernel.h) instantiated for AVX2, eight pixels per
// instruction; atrous.cpp calls it only when the CPU reports AVX2. The rest of the program is
// built for the portable baseline (x86-64-v2), so AVX2 is enabled here with a target pragma
// that covers only the code below it: every header is included *before* the pragma, so that
// no inline function of a shared header is compiled with AVX2 (the linker could otherwise
// pick that copy for the whole program). Contraction into FMA is switched off: every lane
// computes exactly the float operations of the SSE2 and scalar paths, so results do not
// depend on which path ran.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "denoise/util/fast_exp.h"
#include "denoise/util/float_lanes.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#pragma GCC push_options
#pragma GCC target("avx2")
// No contraction of a·b + c into FMA (AVX-512F makes FMA available): the same roundings as
// the other paths, lane for lane.
#pragma GCC optimize("fp-contract=off")

namespace chorus {
namespace {

struct Float8 {
  static constexpr int kWidth = 8;
  __m256 v;
  static Float8 load(const float* p) { return {_mm256_loadu_ps(p)}; }
  static Float8 broadcast(float x) { return {_mm256_set1_ps(x)}; }
  void store(float* p) const { _mm256_storeu_ps(p, v); }
};
Float8 operator+(Float8 a, Float8 b) {
  return {_mm256_add_ps(a.v, b.v)};
}
Float8 operator-(Float8 a, Float8 b) {
  return {_mm256_sub_ps(a.v, b.v)};
}
Float8 operator*(Float8 a, Float8 b) {
  return {_mm256_mul_ps(a.v, b.v)};
}
Float8 operator/(Float8 a, Float8 b) {
  return {_mm256_div_ps(a.v, b.v)};
}
Float8 abs(Float8 a) {
  return {_mm256_and_ps(a.v, _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff)))};
}
Float8 max0(Float8 a) {
  return {_mm256_max_ps(a.v, _mm256_setzero_ps())};
}

// exp(−e), lane for lane the operations of fastExpNonPositive (fast_exp.h).
template <int kDegree>
Float8 expNegated(Float8 e) {
  using namespace fast_exp_detail;
  __m256 t = _mm256_mul_ps(e.v, _mm256_set1_ps(-kLog2e));
  t = _mm256_max_ps(t, _mm256_set1_ps(-127.0f));
  t = _mm256_min_ps(t, _mm256_setzero_ps());
  const __m256 round = _mm256_set1_ps(kRound);
  const __m256 rounded = _mm256_add_ps(t, round);
  const __m256 n = _mm256_sub_ps(rounded, round);
  const __m256i biased = _mm256_add_epi32(_mm256_castps_si256(rounded),
                                          _mm256_set1_epi32(127 - std::bit_cast<int32_t>(kRound)));
  const __m256 y = _mm256_mul_ps(_mm256_sub_ps(t, n), _mm256_set1_ps(kLn2));
  __m256 p = _mm256_set1_ps(kExpPolynomial<kDegree>[0]);
  for (int k = 1; k <= kDegree; ++k)
    p = _mm256_add_ps(_mm256_mul_ps(p, y), _mm256_set1_ps(kExpPolynomial<kDegree>[size_t(k)]));
  return {_mm256_mul_ps(p, _mm256_castsi256_ps(_mm256_slli_epi32(biased, 23)))};
}

}  // namespace
}  // namespace chorus

#include "denoise/base/atrous/atrous_kernel.h"

namespace chorus {

AtrousRowFilter selectAtrousRowFilterAvx2(int squarings, bool unknownNormals) {
  return selectRowFilter<Pair<Float8>>(squarings, unknownNormals);
}

}  // namespace chorus

#pragma GCC pop_options

#else

#include "denoise/base/atrous/atrous_kernel.h"

namespace chorus {

AtrousRowFilter selectAtrousRowFilterAvx2(int, bool) {
  return nullptr;
}

}  // namespace chorus

#endif
