#pragma once
// exp(x) for x ≤ 0, written so that GCC vectorises the loops that call it: std::exp does not
// vectorise without -ffast-math, and a float select next to a computed value stops the
// vectoriser too (with the default -ftrapping-math), so the kernel has no float selects at all
// and callers clamp in a separate loop. Relative error below 3e-7 on [-41, 0]; exactly 0 below
// -60 ln 2 ≈ -41.6 (e^-41.6 ≈ 9e-19): NL-means weights, exp(-max(0, D)), that small change no
// float sum next to a centre weight, and products of them would be denormal floats, which cost
// a hundred times more to compute with on x86.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>

namespace chorus {

// Largest |x| the vector kernel accepts (keeps x·log2e inside int32).
inline constexpr float kMaxExpArgument = 1e6f;
// exp(x) is 0 where round(x log2e) is below this.
inline constexpr int32_t kMinExponent = -60;

// exp(x) for x in [-kMaxExpArgument, 0]; no clamping inside.
inline float expNonPositiveUnclamped(float x) {
  constexpr float kLog2e = 1.44269504088896341f;
  constexpr float kLn2Hi = 0.693359375f;  // ln 2 split in two parts (Cody–Waite reduction)
  constexpr float kLn2Lo = -2.12194440e-4f;
  // x = n ln2 + r with n = round(x log2e) (x log2e ≤ 0, so truncating t − ½ rounds), |r| ≤ ln2/2
  const int32_t n = int32_t(x * kLog2e - 0.5f);
  const float nf = float(n);
  const float r = (x - nf * kLn2Hi) - nf * kLn2Lo;
  // e^r = 1 + r + r² P(r), Cephes expf coefficients
  float p = 1.9875691500e-4f;
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  p = p * r * r + r + 1.0f;
  // 2^n from the exponent field; n < kMinExponent gives exactly 0.
  const int32_t field = (n + 127) & -int32_t(n >= kMinExponent);
  return p * std::bit_cast<float>(uint32_t(field) << 23);
}

// exp(x) for any x ≤ 0 (clamped; scalar use).
inline float expNonPositive(float x) {
  return expNonPositiveUnclamped(std::clamp(x, -kMaxExpArgument, 0.0f));
}

// values[i] = exp(values[i]) in place, every value in [-kMaxExpArgument, 0]. Vectorised.
inline void expNonPositiveInPlace(float* __restrict values, size_t n) {
  for (size_t i = 0; i < n; ++i) values[i] = expNonPositiveUnclamped(values[i]);
}

// exp(x) for x already in [−87, 0] (the caller clamps; no check here): expNonPositive's
// polynomial without its branches, so that loops calling it vectorise (with floating-point traps
// off in the calling file, e.g. `#pragma GCC optimize("no-trapping-math")`).
inline float expClamped(float x) {
  constexpr float kLog2e = 1.44269504088896341f;
  constexpr float kLn2Hi = 0.693359375f;
  constexpr float kLn2Lo = -2.12194440e-4f;
  const float n = float(int32_t(x * kLog2e - 0.5f));
  const float r = (x - n * kLn2Hi) - n * kLn2Lo;
  float p = 1.9875691500e-4f;
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  p = p * r * r + r + 1.0f;
  return p * std::bit_cast<float>(uint32_t(int32_t(n) + 127) << 23);
}

}  // namespace chorus
