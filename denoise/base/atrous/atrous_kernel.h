#pragma once
// The inner kernel of one à-trous level (atrous.h), written once as templates over the lane
// type (float_lanes.h). Included by atrous.cpp, which instantiates it for SSE2, and by
// atrous_avx2.cpp, which instantiates it for AVX2 with that instruction set enabled (see there:
// the includes below must already have been included before its target pragma). Everything
// here except the plain structs has internal linkage, so that the two instruction-set versions
// of the same template never merge at link time.
#include <algorithm>
#include <array>
#include <cstddef>

#include "denoise/util/float_lanes.h"

namespace chorus {

// Everything one à-trous level reads, as padded planes: pointers address pixel (0, 0), pixel
// (x, y) is at y·stride + x, and columns x ∈ [−2·step, w + 2·step) are readable (zeros outside
// the image). `inside[x]` is 1 for x ∈ [0, w), else 0, over the same columns.
struct AtrousLevelInputs {
  int w = 0, h = 0, step = 1;
  ptrdiff_t stride = 0;
  const float* inside;
  const float *z, *gx, *gy, *nx, *ny, *nz, *hasNormal;   // guide
  const float *luminance, *inverseTolerance, *variance;  // this level's luminance statistics
  // The tolerance a tap q imposes on its own: the larger of p's and q's inverse tolerances
  // counts. inverseTolerance itself when the variances are trusted (AtrousParams), else zeros.
  const float* neighbourTolerance;
  const float* color[3];
};

// Filters one row of a level: (inputs, y, output colour planes, output variance plane).
using AtrousRowFilter = void (*)(const AtrousLevelInputs&, int, float* const[3], float*);

// The AVX2 / AVX-512F row filters (atrous_avx2.cpp, atrous_avx512.cpp); nullptr where they
// were not compiled.
AtrousRowFilter selectAtrousRowFilterAvx2(int squarings, bool unknownNormals);
AtrousRowFilter selectAtrousRowFilterAvx512(int squarings, bool unknownNormals);

namespace {

// Two independent vectors behind one type: every operation issues two independent
// instructions, which hides the latency of the long dependency chain of each tap (the
// exponential's polynomial, the normal weight's squarings). Defined here, not in
// float_lanes.h, so that it is compiled with the instruction set of the including file.
template <class F>
struct Pair {
  static constexpr int kWidth = 2 * F::kWidth;
  F a, b;
  static Pair load(const float* p) { return {F::load(p), F::load(p + F::kWidth)}; }
  static Pair broadcast(float x) { return {F::broadcast(x), F::broadcast(x)}; }
  void store(float* p) const {
    a.store(p);
    b.store(p + F::kWidth);
  }
};
template <class F>
Pair<F> operator+(Pair<F> x, Pair<F> y) {
  return {x.a + y.a, x.b + y.b};
}
template <class F>
Pair<F> operator-(Pair<F> x, Pair<F> y) {
  return {x.a - y.a, x.b - y.b};
}
template <class F>
Pair<F> operator*(Pair<F> x, Pair<F> y) {
  return {x.a * y.a, x.b * y.b};
}
template <class F>
Pair<F> operator/(Pair<F> x, Pair<F> y) {
  return {x.a / y.a, x.b / y.b};
}
template <class F>
Pair<F> abs(Pair<F> x) {
  return {abs(x.a), abs(x.b)};
}
template <class F>
Pair<F> max0(Pair<F> x) {
  return {max0(x.a), max0(x.b)};
}
template <int kDegree, class F>
Pair<F> expNegated(Pair<F> x) {
  return {expNegated<kDegree>(x.a), expNegated<kDegree>(x.b)};
}

constexpr std::array<float, 5> kB3Spline = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
constexpr float kDepthEpsilon = 1e-3f;  // on depth / max depth
// The weights' exponential: degree 4 (relative error 3.5e-6) costs two multiply-adds less per
// tap than the full-precision 6 (measured: 7% of à-trous's time).
constexpr int kExpDegree = 4;

// Filters F::kWidth consecutive pixels from (x, y) with the weights of the header. kBorder:
// some tap may lie left or right of the image: its weight is multiplied by inside[qx] = 0 (the
// padding it reads is zero, so the products stay finite), which leaves every sum exactly as if
// the tap were skipped. kSquarings: log2 σ_n, or −1 without the normal weight.
// kUnknownNormals: the guide has pixels without a normal.
template <class F, bool kBorder, int kSquarings, bool kUnknownNormals>
void filterPixels(const AtrousLevelInputs& in, int x, int y, float* const outColor[3],
                  float* outVariance) {
  const ptrdiff_t p = ptrdiff_t(y) * in.stride + x;
  const F zp = F::load(in.z + p), lp = F::load(in.luminance + p);
  const F gx = F::load(in.gx + p), gy = F::load(in.gy + p);
  const F tolerance = F::load(in.inverseTolerance + p);
  const F one = F::broadcast(1.0f);
  const F epsilon = F::broadcast(kDepthEpsilon);
  // ∇z·δ for δ = step·(tx, ty) as the sum of an x and a y term, taken from these tables.
  const F zero = F::broadcast(0.0f), stepGx = gx * F::broadcast(float(in.step));
  const F stepGy = gy * F::broadcast(float(in.step));
  const F xTerm[5] = {zero - (stepGx + stepGx), zero - stepGx, zero, stepGx, stepGx + stepGx};
  const F yTerm[5] = {zero - (stepGy + stepGy), zero - stepGy, zero, stepGy, stepGy + stepGy};
  // 1 / (|∇z·δ| + ε_z) for the taps before the centre (k = 5(ty + 2) + tx + 2 < 12); the tap
  // mirrored through the centre (24 − k) has exactly the same |∇z·δ| (the tables are negations
  // of each other), so twelve divisions serve all 24 off-centre taps.
  F inverseDepthScale[12];
  for (int k = 0; k < 12; ++k)
    inverseDepthScale[k] = one / (abs(xTerm[k % 5] + yTerm[k / 5]) + epsilon);
  F sum[3] = {F::broadcast(0), F::broadcast(0), F::broadcast(0)};
  F weightSum = F::broadcast(0), varianceSum = F::broadcast(0);
  for (int ty = -2; ty <= 2; ++ty) {
    const int qy = y + ty * in.step;
    if (qy < 0 || qy >= in.h) continue;
    for (int tx = -2; tx <= 2; ++tx) {
      const int qx = x + tx * in.step;
      const ptrdiff_t q = ptrdiff_t(qy) * in.stride + qx;
      const F kernel = F::broadcast(kB3Spline[size_t(tx + 2)] * kB3Spline[size_t(ty + 2)]);
      // w_z w_l = exp(−|Δz| / (σ_z |∇z·δ| + ε_z) − |Δl| / (σ_l √Var + ε_l)); σ_z is in ∇z.
      // At the centre both differences are 0 and exp(−0) is exactly 1.
      const int k = 5 * (ty + 2) + tx + 2;
      F w = kernel;
      if (k != 12) {
        const F e = abs(zp - F::load(in.z + q)) * inverseDepthScale[k < 12 ? k : 24 - k] +
                    abs(lp - F::load(in.luminance + q)) *
                        (tolerance + max0(F::load(in.neighbourTolerance + q) - tolerance));
        w = w * expNegated<kExpDegree>(e);
      }
      if constexpr (kSquarings >= 0) {
        // w_n = max(0, n_p·n_q)^(2^kSquarings).
        const F dot = F::load(in.nx + p) * F::load(in.nx + q) +
                      F::load(in.ny + p) * F::load(in.ny + q) +
                      F::load(in.nz + p) * F::load(in.nz + q);
        F wn = max0(dot);
        for (int s = 0; s < kSquarings; ++s) wn = wn * wn;
        if constexpr (kUnknownNormals) {
          // A pixel without a normal does not constrain: w_n = 1 unless both are known.
          const F both = F::load(in.hasNormal + p) * F::load(in.hasNormal + q);
          wn = wn * both + (one - both);
        }
        w = w * wn;
      }
      if constexpr (kBorder) w = w * F::load(in.inside + qx);
      weightSum = weightSum + w;
      varianceSum = varianceSum + w * w * F::load(in.variance + q);
      for (int c = 0; c < 3; ++c) sum[c] = sum[c] + w * F::load(in.color[c] + q);
    }
  }
  // The centre tap always has weight h(0) > 0, so Σ h w > 0.
  for (int c = 0; c < 3; ++c) (sum[c] / weightSum).store(outColor[c] + p);
  (varianceSum / (weightSum * weightSum)).store(outVariance + p);
}

// Filters row y in chunks of Wide::kWidth pixels (masked near the borders), the last few
// pixels one at a time.
template <class Wide, int kSquarings, bool kUnknownNormals>
void filterRow(const AtrousLevelInputs& in, int y, float* const outColor[3], float* outVariance) {
  const FlushDenormals flush;
  const int margin = 2 * in.step;  // pixels in [margin, w − margin) have all taps inside
  int x = 0;
  for (; x + Wide::kWidth <= in.w; x += Wide::kWidth) {
    if (x < margin || x + Wide::kWidth > in.w - margin)
      filterPixels<Wide, true, kSquarings, kUnknownNormals>(in, x, y, outColor, outVariance);
    else
      filterPixels<Wide, false, kSquarings, kUnknownNormals>(in, x, y, outColor, outVariance);
  }
  for (; x < in.w; ++x)
    filterPixels<Float1, true, kSquarings, kUnknownNormals>(in, x, y, outColor, outVariance);
}

template <class Wide, int kSquarings>
AtrousRowFilter rowFilterFor(bool unknownNormals) {
  return unknownNormals ? &filterRow<Wide, kSquarings, true> : &filterRow<Wide, kSquarings, false>;
}

// The row filter for σ_n = 2^squarings (squarings = −1: no normal weight).
template <class Wide>
AtrousRowFilter selectRowFilter(int squarings, bool unknownNormals) {
  switch (squarings) {
    case -1:
      return rowFilterFor<Wide, -1>(unknownNormals);
    case 0:
      return rowFilterFor<Wide, 0>(unknownNormals);
    case 1:
      return rowFilterFor<Wide, 1>(unknownNormals);
    case 2:
      return rowFilterFor<Wide, 2>(unknownNormals);
    case 3:
      return rowFilterFor<Wide, 3>(unknownNormals);
    case 4:
      return rowFilterFor<Wide, 4>(unknownNormals);
    case 5:
      return rowFilterFor<Wide, 5>(unknownNormals);
    case 6:
      return rowFilterFor<Wide, 6>(unknownNormals);
    case 7:
      return rowFilterFor<Wide, 7>(unknownNormals);
    case 8:
      return rowFilterFor<Wide, 8>(unknownNormals);
    case 9:
      return rowFilterFor<Wide, 9>(unknownNormals);
    default:
      return rowFilterFor<Wide, 10>(unknownNormals);
  }
}

}  // namespace
}  // namespace chorus
