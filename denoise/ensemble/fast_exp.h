#pragma once
// exp(−d) for d ≥ 0 in float, branch-free so that loops over pixels vectorise (std::exp does
// not without -ffast-math). With i = round(−d / ln 2) and r = −d − i·ln 2 (Cody–Waite: ln 2
// split into a part that multiplies exactly and a small correction), |r| ≤ ½ ln 2,
// exp(−d) = e^r · 2^i: e^r by its degree-6 Taylor polynomial (relative error < 2e-7 overall),
// 2^i through the exponent bits. d is clamped to 80 (exp(−80) ≈ 1.8e-35, a normal float) by an
// unsigned minimum on its bits, which also sends NaN and negative d (bits ≥ 2³¹) to 80.
// Exactly 1 for d = 0.
#include <bit>
#include <cstdint>

namespace chorus {

inline float fastExpNegative(float d) {
  constexpr uint32_t kBits80 = 0x42A00000u;                 // 80.0f
  const uint32_t bits = std::bit_cast<uint32_t>(d + 0.0f);  // + 0 turns −0 into +0
  d = std::bit_cast<float>(bits < kBits80 ? bits : kBits80);
  const int32_t i = -int32_t(0.5f + d * 1.44269504f);  // round(−d / ln 2) for d ≥ 0
  const float r = (-d - float(i) * 0.693145752f) - float(i) * 1.42860677e-6f;
  const float p =
      1.0f + r * (1.0f + r * (0.5f + r * (1.0f / 6 +
                                          r * (1.0f / 24 + r * (1.0f / 120 + r * (1.0f / 720))))));
  return p * std::bit_cast<float>((i + 127) << 23);
}

}  // namespace chorus
