#pragma once
// exp(x) for x ≤ 0, written so that GCC vectorises loops that call it (std::exp does not
// vectorise without -ffast-math). Relative error below 2e-7 on [-87, 0]; returns 0 below -87
// (where float exp underflows to denormals anyway). NL-means weights are exp(-max(0, D)).
#include <bit>
#include <cstdint>

namespace chorus {

inline float expNonPositive(float x) {
  constexpr float kLog2e = 1.44269504088896341f;
  constexpr float kLn2Hi = 0.693359375f;  // ln 2 split in two parts (Cody–Waite reduction)
  constexpr float kLn2Lo = -2.12194440e-4f;
  const float xc = x < -87.0f ? -87.0f : (x > 0.0f ? 0.0f : x);
  // x = n ln2 + r, |r| ≤ ln2 / 2
  const float n = float(int32_t(xc * kLog2e - 0.5f));  // round half down; xc·log2e ≤ 0
  const float r = (xc - n * kLn2Hi) - n * kLn2Lo;
  // e^r: degree-6 Taylor–minimax polynomial (Cephes expf coefficients)
  float p = 1.9875691500e-4f;
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  p = p * r * r + r + 1.0f;
  const float scale = std::bit_cast<float>(uint32_t(int32_t(n) + 127) << 23);
  return x < -87.0f ? 0.0f : p * scale;
}

}  // namespace chorus
