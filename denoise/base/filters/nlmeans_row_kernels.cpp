#include "denoise/base/filters/nlmeans_row_kernels.h"

// Floating-point operations never trap in chorus (no FP exceptions are enabled), which lets GCC
// turn the selects of these loops (clamps, refinement) into vector blends. It changes no value:
// the same IEEE operations are evaluated, so the inline functions of the headers below, which
// must be compiled the same way to be inlined into the loops, give the same results in every
// translation unit.
#pragma GCC optimize("no-trapping-math")

#include <algorithm>

#include "denoise/base/filters/fast_exp.h"

#include "denoise/util/simd_clones.h"

// AVX-512F, AVX2 and baseline builds of every kernel.
#define ROW_KERNEL CHORUS_SIMD_CLONES

namespace chorus::rows {
namespace {

constexpr float kEpsilon = 1e-10f;
constexpr float kClamp = 1e4f;  // NlMeansTerm's default distance clamp
constexpr float kThird = 1.0f / 3.0f;

inline float clampDistance(float d) {
  return d <= kClamp ? d : kClamp;
}
// exp(−max(0, d)), 0 for d ≥ 87 and for NaN (as expNonPositive, which returns 0 below −87).
inline float weightOf(float d) {
  const float clamped = d < 87.0f ? (d > 0.0f ? d : 0.0f) : 87.0f;
  return expClamped(-clamped) * float(d < 87.0f);
}

// Symmetric-pair refinement factor a (0 where it does not apply), from t = ws / (w1 + w2) − 1.
inline float refineFactorOf(float t, float w1, float w2, float mask, float minWeight) {
  const float a = std::min(std::max(t, 0.0f), 1.0f);
  return (mask > 0.0f) & (w1 >= minWeight) & (w2 >= minWeight) ? a : 0.0f;
}
inline float refineFactor(float w1, float w2, float ws, float mask, float minWeight) {
  return refineFactorOf(ws / (w1 + w2) - 1.0f, w1, w2, mask, minWeight);
}

// One term's refined weights for δ and −δ from its distance sums (× scale, the channel mean),
// min'd into outPlus / outMinus.
inline void refinedTermWeights(float scale, float dPlus, float dMinus, float dSym, float symMask,
                               float minRefineWeight, float& outPlus, float& outMinus) {
  const float w1 = weightOf(scale * dPlus), w2 = weightOf(scale * dMinus);
  const float ws = weightOf(scale * dSym);
  const float a = refineFactor(w1, w2, ws, symMask, minRefineWeight);
  outPlus = std::min(outPlus, a * ws + (1.0f - a) * w1);
  outMinus = std::min(outMinus, a * ws + (1.0f - a) * w2);
}

}  // namespace

ROW_KERNEL
void minTermWeights(int n, float scale, const float* __restrict dPlus,
                    const float* __restrict dMinus, const float* __restrict dSym,
                    const float* __restrict symMask, float minRefineWeight,
                    float* __restrict outPlus, float* __restrict outMinus) {
  for (int i = 0; i < n; ++i)
    refinedTermWeights(scale, dPlus[i], dMinus[i], dSym[i], symMask[i], minRefineWeight, outPlus[i],
                       outMinus[i]);
}

// featureTermWeights for C channels: the channel loop unrolled, the six distance sums in
// registers. Each instantiation is cloned itself: a template inlined into a cloned function is
// not vectorised for the clone's target.
template <int C>
ROW_KERNEL void featureTermWeightsOf(int n, size_t stride, const float* __restrict f,
                                     const float* __restrict fp, const float* __restrict fm,
                                     const float* __restrict vn, const float* __restrict vnp,
                                     const float* __restrict vnm, const float* __restrict kv,
                                     const float* __restrict kvp, const float* __restrict kvm,
                                     float floorA, float floorB, const float* __restrict symMask,
                                     float minRefineWeight, float* __restrict plusA,
                                     float* __restrict minusA, float* __restrict plusB,
                                     float* __restrict minusB) {
  constexpr float scale = 1.0f / float(C);
  for (int i = 0; i < n; ++i) {
    float plusDA = 0.0f, minusDA = 0.0f, symDA = 0.0f, plusDB = 0.0f, minusDB = 0.0f, symDB = 0.0f;
#pragma GCC unroll 4
    for (int c = 0; c < C; ++c) {
      const size_t k = size_t(c) * stride + size_t(i);
      const float v = vn[k], mp = std::min(v, vnp[k]), mm = std::min(v, vnm[k]);
      const float diffP = f[k] - fp[k], diffM = f[k] - fm[k];
      const float diffS = f[k] - 0.5f * (fp[k] + fm[k]);
      const float numP = diffP * diffP - (v + mp), numM = diffM * diffM - (v + mm);
      const float numS = diffS * diffS - (v + 0.25f * (mp + mm));
      const float denA = std::max(kv[k], floorA), denB = std::max(kv[k], floorB);
      const float denAP = std::max(kvp[k], floorA), denAM = std::max(kvm[k], floorA);
      const float denBP = std::max(kvp[k], floorB), denBM = std::max(kvm[k], floorB);
      plusDA += clampDistance(numP / (denA + denAP + kEpsilon));
      minusDA += clampDistance(numM / (denA + denAM + kEpsilon));
      symDA += clampDistance(numS / (denA + 0.25f * (denAP + denAM) + kEpsilon));
      plusDB += clampDistance(numP / (denB + denBP + kEpsilon));
      minusDB += clampDistance(numM / (denB + denBM + kEpsilon));
      symDB += clampDistance(numS / (denB + 0.25f * (denBP + denBM) + kEpsilon));
    }
    refinedTermWeights(scale, plusDA, minusDA, symDA, symMask[i], minRefineWeight, plusA[i],
                       minusA[i]);
    refinedTermWeights(scale, plusDB, minusDB, symDB, symMask[i], minRefineWeight, plusB[i],
                       minusB[i]);
  }
}

// Skipping (featureTermWeights): chunks of kChunk pixels.
constexpr int kChunk = 16, kMaxChunks = 64;

// matters[k] = 1 where some numerator of the distances of chunk k (pixels [16 k, 16 k + 16)) is
// positive or NaN. Elsewhere every distance is ≤ 0 (the denominators are positive), all three
// weights of both sets are exactly 1, the refinement factor is 0, and the minima, which start at
// 1 and only fall, keep their values: the chunk changes nothing.
template <int C>
ROW_KERNEL void featureTermChunks(int chunks, size_t stride, const float* __restrict f,
                                  const float* __restrict fp, const float* __restrict fm,
                                  const float* __restrict vn, const float* __restrict vnp,
                                  const float* __restrict vnm, unsigned char* __restrict matters) {
  for (int chunk = 0; chunk < chunks; ++chunk) {
    int any = 0;
    for (int j = 0; j < kChunk; ++j) {
#pragma GCC unroll 4
      for (int c = 0; c < C; ++c) {
        const size_t k = size_t(c) * stride + size_t(chunk * kChunk + j);
        const float v = vn[k], mp = std::min(v, vnp[k]), mm = std::min(v, vnm[k]);
        const float diffP = f[k] - fp[k], diffM = f[k] - fm[k];
        const float diffS = f[k] - 0.5f * (fp[k] + fm[k]);
        const float numP = diffP * diffP - (v + mp), numM = diffM * diffM - (v + mm);
        const float numS = diffS * diffS - (v + 0.25f * (mp + mm));
        any |= int(!(numP <= 0.0f)) | int(!(numM <= 0.0f)) | int(!(numS <= 0.0f));
      }
    }
    matters[chunk] = (unsigned char)any;
  }
}

// featureTermWeightsOf<C> on the runs of chunks that matter (and the partial last chunk). The
// runs start at multiples of 16, so every pixel goes through the same vector or tail code as in
// one call over the row (the AVX-512 build's tail may differ in the last bit).
template <int C>
void featureTermRuns(int n, size_t stride, const float* f, const float* fp, const float* fm,
                     const float* vn, const float* vnp, const float* vnm, const float* kv,
                     const float* kvp, const float* kvm, float floorA, float floorB,
                     const float* symMask, float minRefineWeight, float* plusA, float* minusA,
                     float* plusB, float* minusB) {
  const int chunks = n / kChunk;
  if (chunks > kMaxChunks) {
    featureTermWeightsOf<C>(n, stride, f, fp, fm, vn, vnp, vnm, kv, kvp, kvm, floorA, floorB,
                            symMask, minRefineWeight, plusA, minusA, plusB, minusB);
    return;
  }
  unsigned char matters[kMaxChunks];
  featureTermChunks<C>(chunks, stride, f, fp, fm, vn, vnp, vnm, matters);
  auto needed = [&](int chunk) { return chunk >= chunks || matters[chunk]; };
  for (int chunk = 0; chunk * kChunk < n;) {
    if (!needed(chunk)) {
      ++chunk;
      continue;
    }
    int end = chunk;
    while (end * kChunk < n && needed(end)) ++end;
    const size_t a = size_t(chunk * kChunk);
    const int count = std::min(n, end * kChunk) - chunk * kChunk;
    featureTermWeightsOf<C>(count, stride, f + a, fp + a, fm + a, vn + a, vnp + a, vnm + a, kv + a,
                            kvp + a, kvm + a, floorA, floorB, symMask + a, minRefineWeight,
                            plusA + a, minusA + a, plusB + a, minusB + a);
    chunk = end;
  }
}

void featureTermWeights(int n, int channels, size_t planeStride, const float* f, const float* fp,
                        const float* fm, const float* vn, const float* vnp, const float* vnm,
                        const float* kv, const float* kvp, const float* kvm, float floorA,
                        float floorB, const float* symMask, float minRefineWeight, float* plusA,
                        float* minusA, float* plusB, float* minusB) {
  switch (channels) {
#define CHORUS_TERM_CASE(C)                                                                  \
  case C:                                                                                    \
    return featureTermRuns<C>(n, planeStride, f, fp, fm, vn, vnp, vnm, kv, kvp, kvm, floorA, \
                              floorB, symMask, minRefineWeight, plusA, minusA, plusB, minusB);
    CHORUS_TERM_CASE(1)
    CHORUS_TERM_CASE(2)
    CHORUS_TERM_CASE(3)
    CHORUS_TERM_CASE(4)
#undef CHORUS_TERM_CASE
    default:
      return;  // callers check the channel count
  }
}

// One pixel's colour distances from the reciprocals of their denominators.
inline void colorDistancesWith(float g, float gp, float gm, float vn, float vnp, float vnm,
                               float invP, float invM, float invS, float channelShare, float clamp,
                               float& plus, float& minus, float& sym) {
  const float mp = std::min(vn, vnp), mm = std::min(vn, vnm);
  const float diffP = g - gp, diffM = g - gm;
  const float diffS = g - 0.5f * (gp + gm);
  const float dp = channelShare * ((diffP * diffP - (vn + mp)) * invP);
  const float dm = channelShare * ((diffM * diffM - (vn + mm)) * invM);
  const float ds = channelShare * ((diffS * diffS - (vn + 0.25f * (mp + mm))) * invS);
  plus += dp <= clamp ? dp : clamp;
  minus += dm <= clamp ? dm : clamp;
  sym += ds <= clamp ? ds : clamp;
}

// One pixel's colour distances (addColorDistances).
inline void colorDistances(float g, float gp, float gm, float vn, float vnp, float vnm, float vd,
                           float vdp, float vdm, float channelShare, float neighbourShare,
                           float clamp, float& plus, float& minus, float& sym) {
  const float invP = 1.0f / (vd + vdp + kEpsilon);
  const float invM = 1.0f / (vd + vdm + kEpsilon);
  const float invS = 1.0f / (vd + neighbourShare * (vdp + vdm) + kEpsilon);
  colorDistancesWith(g, gp, gm, vn, vnp, vnm, invP, invM, invS, channelShare, clamp, plus, minus,
                     sym);
}

ROW_KERNEL
void centreReciprocals(int n, const float* __restrict vd, float* __restrict invPair,
                       float* __restrict invSym) {
  // The expressions of colorDistances with vdp = vdm = vd and neighbourShare ½, so the same bits.
  const float neighbourShare = 0.5f;
  for (int i = 0; i < n; ++i) {
    invPair[i] = 1.0f / (vd[i] + vd[i] + kEpsilon);
    invSym[i] = 1.0f / (vd[i] + neighbourShare * (vd[i] + vd[i]) + kEpsilon);
  }
}

ROW_KERNEL
void addCentreColorDistances(int n, const float* __restrict g, const float* __restrict gp,
                             const float* __restrict gm, const float* __restrict vn,
                             const float* __restrict vnp, const float* __restrict vnm,
                             const float* __restrict invPair, const float* __restrict invSym,
                             float channelShare, bool first, float* __restrict plus,
                             float* __restrict minus, float* __restrict sym) {
  const float clamp = kClamp * channelShare;
  if (first) {
    for (int i = 0; i < n; ++i) {
      float p = 0.0f, m = 0.0f, q = 0.0f;
      colorDistancesWith(g[i], gp[i], gm[i], vn[i], vnp[i], vnm[i], invPair[i], invPair[i],
                         invSym[i], channelShare, clamp, p, m, q);
      plus[i] = p;
      minus[i] = m;
      sym[i] = q;
    }
    return;
  }
  for (int i = 0; i < n; ++i)
    colorDistancesWith(g[i], gp[i], gm[i], vn[i], vnp[i], vnm[i], invPair[i], invPair[i], invSym[i],
                       channelShare, clamp, plus[i], minus[i], sym[i]);
}

ROW_KERNEL
void addColorDistances(int n, const float* __restrict g, const float* __restrict gp,
                       const float* __restrict gm, const float* __restrict vn,
                       const float* __restrict vnp, const float* __restrict vnm,
                       const float* __restrict vd, const float* __restrict vdp,
                       const float* __restrict vdm, float channelShare, float neighbourShare,
                       bool first, float* __restrict plus, float* __restrict minus,
                       float* __restrict sym, float* __restrict sPlus, float* __restrict sMinus,
                       float* __restrict sSym) {
  const float clamp = kClamp * channelShare;
  // The first channel adds to 0 rather than to the sums (which need no clearing then).
  if (!sPlus) {
    if (first) {
      for (int i = 0; i < n; ++i) {
        float p = 0.0f, m = 0.0f, q = 0.0f;
        colorDistances(g[i], gp[i], gm[i], vn[i], vnp[i], vnm[i], vd[i], vdp[i], vdm[i],
                       channelShare, neighbourShare, clamp, p, m, q);
        plus[i] = p;
        minus[i] = m;
        sym[i] = q;
      }
      return;
    }
    for (int i = 0; i < n; ++i)
      colorDistances(g[i], gp[i], gm[i], vn[i], vnp[i], vnm[i], vd[i], vdp[i], vdm[i], channelShare,
                     neighbourShare, clamp, plus[i], minus[i], sym[i]);
    return;
  }
  // With the slopes in the same loop (one pass over the planes), from the distances'
  // reciprocals: 3 divisions per pixel rather than 6 (the slopes differ from a division in the
  // last bit, which may flip RDFC's selection at a few pixels; relMSE checked unchanged).
  const float twice = 2.0f * channelShare;
  if (first) {
    for (int i = 0; i < n; ++i) {
      const float invP = 1.0f / (vd[i] + vdp[i] + kEpsilon);
      const float invM = 1.0f / (vd[i] + vdm[i] + kEpsilon);
      const float invS = 1.0f / (vd[i] + neighbourShare * (vdp[i] + vdm[i]) + kEpsilon);
      float p = 0.0f, m = 0.0f, q = 0.0f;
      colorDistancesWith(g[i], gp[i], gm[i], vn[i], vnp[i], vnm[i], invP, invM, invS, channelShare,
                         clamp, p, m, q);
      plus[i] = p;
      minus[i] = m;
      sym[i] = q;
      sPlus[i] = twice * (g[i] - gp[i]) * invP;
      sMinus[i] = twice * (g[i] - gm[i]) * invM;
      sSym[i] = twice * (g[i] - 0.5f * (gp[i] + gm[i])) * invS;
    }
    return;
  }
  for (int i = 0; i < n; ++i) {
    const float invP = 1.0f / (vd[i] + vdp[i] + kEpsilon);
    const float invM = 1.0f / (vd[i] + vdm[i] + kEpsilon);
    const float invS = 1.0f / (vd[i] + neighbourShare * (vdp[i] + vdm[i]) + kEpsilon);
    colorDistancesWith(g[i], gp[i], gm[i], vn[i], vnp[i], vnm[i], invP, invM, invS, channelShare,
                       clamp, plus[i], minus[i], sym[i]);
    // d/dg(p) of diff² · inv = 2 diff · inv
    sPlus[i] = twice * (g[i] - gp[i]) * invP;
    sMinus[i] = twice * (g[i] - gm[i]) * invM;
    sSym[i] = twice * (g[i] - 0.5f * (gp[i] + gm[i])) * invS;
  }
}

ROW_KERNEL
void addFeatureDistances(int n, const float* __restrict f, const float* __restrict fp,
                         const float* __restrict fm, const float* __restrict vn,
                         const float* __restrict vnp, const float* __restrict vnm,
                         const float* __restrict den, const float* __restrict denp,
                         const float* __restrict denm, float neighbourShare, float* __restrict plus,
                         float* __restrict minus, float* __restrict sym) {
  if (!sym) {
    for (int i = 0; i < n; ++i) {
      const float mp = std::min(vn[i], vnp[i]), mm = std::min(vn[i], vnm[i]);
      const float diffP = f[i] - fp[i], diffM = f[i] - fm[i];
      plus[i] += clampDistance((diffP * diffP - (vn[i] + mp)) / (den[i] + denp[i] + kEpsilon));
      minus[i] += clampDistance((diffM * diffM - (vn[i] + mm)) / (den[i] + denm[i] + kEpsilon));
    }
    return;
  }
  for (int i = 0; i < n; ++i) {
    const float mp = std::min(vn[i], vnp[i]), mm = std::min(vn[i], vnm[i]);
    const float diffP = f[i] - fp[i], diffM = f[i] - fm[i];
    const float diffS = f[i] - 0.5f * (fp[i] + fm[i]);
    plus[i] += clampDistance((diffP * diffP - (vn[i] + mp)) / (den[i] + denp[i] + kEpsilon));
    minus[i] += clampDistance((diffM * diffM - (vn[i] + mm)) / (den[i] + denm[i] + kEpsilon));
    sym[i] += clampDistance((diffS * diffS - (vn[i] + 0.25f * (mp + mm))) /
                            (den[i] + neighbourShare * (denp[i] + denm[i]) + kEpsilon));
  }
}

// The box sums below add the taps in a register, in the same order as a row-by-row
// accumulation would (so the same sums), for the radii the filters use (patch radii 1 and 3,
// weight box 2); other radii take the generic loops.
template <int R>
inline void horizontalBoxSumOf(int n, const float* __restrict src, float* __restrict dst) {
  for (int i = 0; i < n; ++i) {
    float sum = src[i - R];
#pragma GCC unroll 8
    for (int j = -R + 1; j <= R; ++j) sum += src[i + j];
    dst[i] = sum;
  }
}

template <int Count>
inline void verticalBoxMeanOf(int n, const float* __restrict src, size_t stride, float scaleY,
                              const float* __restrict scaleX, float* __restrict dst) {
  for (int i = 0; i < n; ++i) {
    float sum = src[i];
#pragma GCC unroll 8
    for (int j = 1; j < Count; ++j) sum += src[size_t(j) * stride + size_t(i)];
    dst[i] = sum * (scaleY * scaleX[i]);
  }
}

ROW_KERNEL
void horizontalBoxSum(int n, const float* __restrict src, int r, float* __restrict dst) {
  switch (r) {
    case 1:
      return horizontalBoxSumOf<1>(n, src, dst);
    case 2:
      return horizontalBoxSumOf<2>(n, src, dst);
    case 3:
      return horizontalBoxSumOf<3>(n, src, dst);
    default:
      break;
  }
  for (int i = 0; i < n; ++i) dst[i] = src[i - r];
  for (int j = -r + 1; j <= r; ++j)
    for (int i = 0; i < n; ++i) dst[i] += src[i + j];
}

ROW_KERNEL
void verticalBoxMean(int n, const float* __restrict src, size_t stride, int count, float scaleY,
                     const float* __restrict scaleX, float* __restrict dst) {
  switch (count) {
    case 3:
      return verticalBoxMeanOf<3>(n, src, stride, scaleY, scaleX, dst);
    case 5:
      return verticalBoxMeanOf<5>(n, src, stride, scaleY, scaleX, dst);
    case 7:
      return verticalBoxMeanOf<7>(n, src, stride, scaleY, scaleX, dst);
    default:
      break;
  }
  for (int i = 0; i < n; ++i) dst[i] = src[i];
  for (int j = 1; j < count; ++j) {
    const float* __restrict row = src + size_t(j) * stride;
    for (int i = 0; i < n; ++i) dst[i] += row[i];
  }
  for (int i = 0; i < n; ++i) dst[i] *= scaleY * scaleX[i];
}

ROW_KERNEL
void widenBoxSum(int n, const float* __restrict src, const float* __restrict inner, int r0,
                 float* __restrict dst) {
  const int k = r0 + 1;
  for (int i = 0; i < n; ++i) dst[i] = (inner[i - k] + src[i]) + inner[i + k];
}

ROW_KERNEL
void runningBoxMeans(int n, int rows, const float* __restrict src, size_t stride, int count,
                     const float* __restrict scaleY, const float* __restrict scaleX,
                     float* __restrict running, float* __restrict dst, size_t dstStride) {
  if (rows <= 0) return;
  for (int i = 0; i < n; ++i) running[i] = src[i];
  for (int j = 1; j < count; ++j) {
    const float* __restrict row = src + size_t(j) * stride;
    for (int i = 0; i < n; ++i) running[i] += row[i];
  }
  for (int i = 0; i < n; ++i) dst[i] = running[i] * (scaleY[0] * scaleX[i]);
  for (int y = 1; y < rows; ++y) {
    const float* __restrict leaving = src + size_t(y - 1) * stride;
    const float* __restrict entering = src + size_t(y - 1 + count) * stride;
    float* __restrict out = dst + size_t(y) * dstStride;
    const float sy = scaleY[y];
    for (int i = 0; i < n; ++i) {
      running[i] += entering[i] - leaving[i];
      out[i] = running[i] * (sy * scaleX[i]);
    }
  }
}

ROW_KERNEL
void minWeights(int n, const float* __restrict a, const float* __restrict b,
                float* __restrict out) {
  for (int i = 0; i < n; ++i) out[i] = std::min(a[i], b[i]);
}

ROW_KERNEL
void maxScaled(int n, float scale, const float* __restrict src, float* __restrict dst) {
  for (int i = 0; i < n; ++i) dst[i] = std::max(dst[i], scale * src[i]);
}

ROW_KERNEL
void maskedWeights(int n, const float* __restrict d, const float* __restrict mask,
                   float* __restrict w) {
  for (int i = 0; i < n; ++i) w[i] = mask[i] * weightOf(d[i]);
}

ROW_KERNEL
void patchWeights(int n, const float* __restrict dPlus, const float* __restrict dMinus,
                  const float* __restrict dSym, const float* __restrict maskPlus,
                  const float* __restrict maskMinus, const float* __restrict maskSym,
                  float minRefineWeight, float* __restrict wPlus, float* __restrict wMinus) {
  for (int i = 0; i < n; ++i) {
    const float w1 = maskPlus[i] * weightOf(dPlus[i]), w2 = maskMinus[i] * weightOf(dMinus[i]);
    const float ws = weightOf(dSym[i]);
    const float a = refineFactor(w1, w2, ws, maskSym[i], minRefineWeight);
    wPlus[i] = a * ws + (1.0f - a) * w1;
    wMinus[i] = a * ws + (1.0f - a) * w2;
  }
}

ROW_KERNEL
void nearColorSlopes(int n, const float* __restrict g, const float* __restrict gp,
                     const float* __restrict gm, const float* __restrict g2p,
                     const float* __restrict g2m, const float* __restrict vd,
                     const float* __restrict vdp, const float* __restrict vdm,
                     const float* __restrict vd2p, const float* __restrict vd2m,
                     const float* __restrict maskPlusPair, const float* __restrict maskMinusPair,
                     const float* __restrict maskBehind, const float* __restrict maskAhead,
                     float* __restrict nearPlus, float* __restrict nearMinus,
                     float* __restrict nearSym) {
  for (int i = 0; i < n; ++i) {
    // Pair (a, p): d/dg(p) of (g(a) − g(p))² · inv = −2 (g(a) − g(p)) · inv.
    const float plusPair = -2.0f * kThird * (gm[i] - g[i]) / (vdm[i] + vd[i] + kEpsilon);
    const float minusPair = -2.0f * kThird * (gp[i] - g[i]) / (vdp[i] + vd[i] + kEpsilon);
    // Symmetric distance of a with p one of its two neighbours: d/dg(p) of
    // (g(a) − (g(b) + g(c))/2)² · inv = −(g(a) − (g(b) + g(c))/2) · inv.
    const float sb = gm[i] - 0.5f * (g[i] + g2m[i]), sa = gp[i] - 0.5f * (g2p[i] + g[i]);
    const float behind = -kThird * sb / (vdm[i] + 0.25f * (vd[i] + vd2m[i]) + kEpsilon);
    const float ahead = -kThird * sa / (vdp[i] + 0.25f * (vd2p[i] + vd[i]) + kEpsilon);
    nearPlus[i] = maskMinusPair[i] * plusPair;
    nearMinus[i] = maskPlusPair[i] * minusPair;
    nearSym[i] = maskBehind[i] * behind + maskAhead[i] * ahead;
  }
}

namespace {

// The candidate kernels take their many row pointers in structs: copied to locals, with ivdep
// (the rows of one call never overlap) so that GCC vectorises without alias checks. SumsRow is
// a candidate's sums so copied, with the per-pixel update both kernels end with.
struct SumsRow {
  const float* up[6];
  const float* um[6];
  float* weightSum;
  float* maxWeight;
  float* acc;
  size_t stride;

  explicit SumsRow(const CandidateSums& sums)
      : weightSum(sums.weightSum),
        maxWeight(sums.maxWeight),
        acc(sums.acc),
        stride(sums.accStride) {
    for (int k = 0; k < 6; ++k) {
      up[k] = sums.dataPlus[k];
      um[k] = sums.dataMinus[k];
    }
  }
  // Σw, max w and Σ w u with the weights v1, v2 of p + δ and p − δ.
  void add(int i, float v1, float v2) const {
    weightSum[i] += v1 + v2;
    maxWeight[i] = std::max(maxWeight[i], std::max(v1, v2));
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
      float& a = acc[size_t(k) * stride + size_t(i)];
      a += v1 * up[k][i] + v2 * um[k][i];
    }
  }
};

}  // namespace

ROW_KERNEL
void accumulateCandidate(int n, const float* __restrict wPlus, const float* __restrict wMinus,
                         const CandidateSums& sums) {
  const SumsRow out(sums);
#pragma GCC ivdep
  for (int i = 0; i < n; ++i) out.add(i, wPlus[i], wMinus[i]);
}

template <bool Near>
ROW_KERNEL void accumulateColorCandidateOf(int n, const ColorCandidateRow& row,
                                           float minRefineWeight, const CandidateSums& sums) {
  const float* dPlus = row.dist[0];
  const float* dMinus = row.dist[1];
  const float* dSym = row.dist[2];
  const float* invCountPlus = row.invCount[0];
  const float* invCountMinus = row.invCount[1];
  const float* invCountSym = row.invCount[2];
  const float* maskPlus = row.mask[0];
  const float* maskMinus = row.mask[1];
  const float* maskSym = row.mask[2];
  const float* fPlus = row.featPlus;
  const float* fMinus = row.featMinus;
  const float* slope[3][3];
  const float* nearSlope[3][3];
  const float* gPlus[3];
  const float* gMinus[3];
  for (int c = 0; c < 3; ++c) {
    for (int kind = 0; kind < 3; ++kind) {
      slope[c][kind] = row.slope[c][kind];
      nearSlope[c][kind] = Near ? row.nearSlope[c][kind] : nullptr;
    }
    gPlus[c] = row.guidePlus[c];
    gMinus[c] = row.guideMinus[c];
  }
  float* __restrict derivativeSum = row.derivativeSum;
  float* __restrict derivativeAcc = row.derivativeAcc;
  float* __restrict maxDerivative = row.maxDerivative;
  const size_t dStride = row.derivativeStride;
  const SumsRow out(sums);
#pragma GCC ivdep
  for (int i = 0; i < n; ++i) {
    // The weights and the terms of their derivatives.
    const float w1 = maskPlus[i] * weightOf(dPlus[i]), w2 = maskMinus[i] * weightOf(dMinus[i]);
    const float ws = weightOf(dSym[i]);
    // One division for both the refinement and its derivative: a from ws · (1 / sum) rather
    // than ws / sum (a rounding-level change), 1 / sum² as its square.
    const float sum = w1 + w2, invSum = 1.0f / sum, t = ws * invSum - 1.0f;
    const float a = refineFactorOf(t, w1, w2, maskSym[i], minRefineWeight);
    const float r1 = a * ws + (1.0f - a) * w1, r2 = a * ws + (1.0f - a) * w2;
    const float v1 = std::min(r1, fPlus[i]), v2 = std::min(r2, fMinus[i]);
    const float m = out.maxWeight[i];
    const float pick2 = float((v2 > m) & (v2 > v1));
    // ∂w / ∂D · (1 / patch count): −w where 0 < D < 87, else 0
    const float k1 = -w1 * invCountPlus[i] * float(dPlus[i] > 0.0f);
    const float k2 = -w2 * invCountMinus[i] * float(dMinus[i] > 0.0f);
    const float ks = -ws * invCountSym[i] * float(dSym[i] > 0.0f);
    // Where a ∈ (0, 1); there sum ≥ 2e^−25, so 1 / sum < 4e10 and the bound (1 / 0 = ∞
    // elsewhere) changes nothing where it is used.
    const float boundedInv = std::min(invSum, 1e15f);
    const float invSum2 = float((a > 0.0f) & (t < 1.0f)) * (boundedInv * boundedInv);
    const float pass1 = float(r1 < fPlus[i]), pass2 = float(r2 < fMinus[i]);
    const float pick1 = float(v1 > m) * (1.0f - pick2);
    // Their derivatives with respect to each channel of y(p), against the maximum before δ.
#pragma GCC unroll 3
    for (int c = 0; c < 3; ++c) {
      float sp = slope[c][0][i], sm = slope[c][1][i], ss = slope[c][2][i];
      if constexpr (Near) {
        sp = sp + nearSlope[c][0][i];
        sm = sm + nearSlope[c][1][i];
        ss = ss + nearSlope[c][2][i];
      }
      const float dw1 = k1 * sp, dw2 = k2 * sm;
      const float dws = ks * ss;
      const float da = (dws * sum - ws * (dw1 + dw2)) * invSum2;
      const float dv1 = pass1 * (da * (ws - w1) + a * dws + (1.0f - a) * dw1);
      const float dv2 = pass2 * (da * (ws - w2) + a * dws + (1.0f - a) * dw2);
      const size_t k = size_t(c) * dStride + size_t(i);
      derivativeSum[k] += dv1 + dv2;
      derivativeAcc[k] += dv1 * gPlus[c][i] + dv2 * gMinus[c][i];
      maxDerivative[k] = pick2 * dv2 + pick1 * dv1 + (1.0f - pick1 - pick2) * maxDerivative[k];
    }
    out.add(i, v1, v2);
  }
}

void accumulateColorCandidate(int n, const ColorCandidateRow& row, float minRefineWeight,
                              const CandidateSums& sums) {
  if (row.nearSlope[0][0])
    accumulateColorCandidateOf<true>(n, row, minRefineWeight, sums);
  else
    accumulateColorCandidateOf<false>(n, row, minRefineWeight, sums);
}

ROW_KERNEL
void accumulateWeightSums(int n, const float* __restrict wPlus, const float* __restrict wMinus,
                          float* __restrict weightSum, float* __restrict maxWeight) {
  for (int i = 0; i < n; ++i) {
    weightSum[i] += wPlus[i] + wMinus[i];
    maxWeight[i] = std::max(maxWeight[i], std::max(wPlus[i], wMinus[i]));
  }
}

ROW_KERNEL
void accumulateData(int n, const float* __restrict wPlus, const float* __restrict wMinus,
                    const float* __restrict up, const float* __restrict um, float* __restrict acc) {
  for (int i = 0; i < n; ++i) acc[i] += wPlus[i] * up[i] + wMinus[i] * um[i];
}

}  // namespace chorus::rows
