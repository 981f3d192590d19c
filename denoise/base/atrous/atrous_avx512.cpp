// The à-trous level kernel (atrous_kernel.h) instantiated for AVX-512F, sixteen pixels per
// instruction; atrous.cpp calls it only when the CPU reports AVX-512F. Built like
// atrous_avx2.cpp (see there for why every header comes before the target pragma). The rest of the
// program is built for the portable baseline (x86-64-v2), so AVX2 is enabled here with a target
// pragma that covers only the code below it: every header is included *before* the pragma, so that
// no inline function of a shared header is compiled with AVX2 (the linker could otherwise
// pick that copy for the whole program). FMA stays off: without contraction every lane
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
#pragma GCC target("avx512f")
// No contraction of a·b + c into FMA (AVX-512F makes FMA available): the same roundings as
// the other paths, lane for lane.
#pragma GCC optimize("fp-contract=off")
// GCC 12 reports the deliberately undefined pass-through operand of the unmasked AVX-512
// intrinsics (_mm512_undefined_*) as maybe-uninitialized; it is never read.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

namespace chorus {
namespace avx512 {
namespace {

struct Float16 {
  static constexpr int kWidth = 16;
  __m512 v;
  static Float16 load(const float* p) { return {_mm512_loadu_ps(p)}; }
  static Float16 broadcast(float x) { return {_mm512_set1_ps(x)}; }
  void store(float* p) const { _mm512_storeu_ps(p, v); }
};
Float16 operator+(Float16 a, Float16 b) {
  return {_mm512_add_ps(a.v, b.v)};
}
Float16 operator-(Float16 a, Float16 b) {
  return {_mm512_sub_ps(a.v, b.v)};
}
Float16 operator*(Float16 a, Float16 b) {
  return {_mm512_mul_ps(a.v, b.v)};
}
Float16 operator/(Float16 a, Float16 b) {
  return {_mm512_div_ps(a.v, b.v)};
}
Float16 abs(Float16 a) {
  return {_mm512_castsi512_ps(
      _mm512_and_si512(_mm512_castps_si512(a.v), _mm512_set1_epi32(0x7fffffff)))};
}
Float16 max0(Float16 a) {
  return {_mm512_max_ps(a.v, _mm512_setzero_ps())};
}
template <int kDegree>
Float16 expNegated(Float16 e) {
  using namespace fast_exp_detail;
  __m512 t = _mm512_mul_ps(e.v, _mm512_set1_ps(-kLog2e));
  t = _mm512_max_ps(t, _mm512_set1_ps(-127.0f));
  t = _mm512_min_ps(t, _mm512_setzero_ps());
  const __m512 round = _mm512_set1_ps(kRound);
  const __m512 rounded = _mm512_add_ps(t, round);
  const __m512 n = _mm512_sub_ps(rounded, round);
  const __m512i biased = _mm512_add_epi32(_mm512_castps_si512(rounded),
                                          _mm512_set1_epi32(127 - std::bit_cast<int32_t>(kRound)));
  const __m512 y = _mm512_mul_ps(_mm512_sub_ps(t, n), _mm512_set1_ps(kLn2));
  __m512 p = _mm512_set1_ps(kExpPolynomial<kDegree>[0]);
  for (int k = 1; k <= kDegree; ++k)
    p = _mm512_add_ps(_mm512_mul_ps(p, y), _mm512_set1_ps(kExpPolynomial<kDegree>[size_t(k)]));
  return {_mm512_mul_ps(p, _mm512_castsi512_ps(_mm512_slli_epi32(biased, 23)))};
}

}  // namespace
}  // namespace avx512
}  // namespace chorus

#include "denoise/base/atrous/atrous_kernel.h"

namespace chorus {

AtrousRowFilter selectAtrousRowFilterAvx512(int squarings, bool unknownNormals) {
  return selectRowFilter<Pair<avx512::Float16>>(squarings, unknownNormals);
}

}  // namespace chorus

#pragma GCC pop_options

#else

#include "denoise/base/atrous/atrous_kernel.h"

namespace chorus {

AtrousRowFilter selectAtrousRowFilterAvx512(int, bool) {
  return nullptr;
}

}  // namespace chorus

#endif
