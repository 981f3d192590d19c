#pragma once
// The inner loops of the NL-means filters with feature terms (feature_nlmeans.cpp,
// rdfc_candidates.cpp): one call processes one row segment of n pixels for one window offset δ.
// Every loop is branch-free over contiguous arrays so that it vectorises; validity (neighbours
// outside the image) comes in as 0/1 masks. The kernels are compiled for AVX-512F, AVX2 and the
// baseline architecture (CHORUS_SIMD_CLONES; the loader picks one). The AVX-512F build contracts
// a·b + c into FMAs, so its results may differ from the others' in the last bit; each machine
// always runs the same build, so results stay deterministic there.
//
// Conventions: `p` arrays hold the centre pixels' values, `q` / `qp` / `qm` the values at p + δ /
// p + δ / p − δ (pointers into zero-padded planes). "num" variances are α V, "den" variances
// k² Vn, as in nlmeans_weights.h.

#include <cstddef>

namespace chorus::rows {

// One feature term's weights for δ and −δ under two denominator sets A, B (RDFC's two τ), min'd
// into plusA / minusA / plusB / minusB. Per channel (1 to 4 planes, planeStride floats apart;
// other counts do nothing) the clamped pixel distances
// [(f − fq)² − (vn + min(vn, vnq))] / (den + denq + ε) to p ± δ, and to their mean (numerator
// variance vn + ¼ (min(vn, vnp) + min(vn, vnm)), denominator den + ¼ (denp + denm) + ε), with
// den = max(kv, floorA) or max(kv, floorB); their channel means give the weights as in
// minTermWeights. One pass over the term's planes for both sets, the sums kept in registers.
void featureTermWeights(int n, int channels, size_t planeStride, const float* f, const float* fp,
                        const float* fm, const float* vn, const float* vnp, const float* vnm,
                        const float* kv, const float* kvp, const float* kvm, float floorA,
                        float floorB, const float* symMask, float minRefineWeight, float* plusA,
                        float* minusA, float* plusB, float* minusB);

// Weights exp(−max(0, scale · d)) of one term for δ and −δ, refined with the symmetric weight
// where symMask = 1 and both weights ≥ minRefineWeight, then out = min(out, weight).
void minTermWeights(int n, float scale, const float* dPlus, const float* dMinus, const float* dSym,
                    const float* symMask, float minRefineWeight, float* outPlus, float* outMinus);

// One channel's share (channelShare = 1 / channels of the channel average, clamped) of the
// patch-term pixel distances to p + δ, p − δ and to their mean, added to plus / minus / sym;
// the symmetric denominator is vd + neighbourShare (vdp + vdm) (0.25; with vdp = vdm = vd and
// 0.5, the centre-only 2 vd). With slope outputs (non-null), also their derivatives with respect
// to g(p) (unclamped), written to sPlus / sMinus / sSym. `first`: the sums are written as
// 0 + share (their old values are ignored) — the first channel, so that they need no clearing.
void addColorDistances(int n, const float* g, const float* gp, const float* gm, const float* vn,
                       const float* vnp, const float* vnm, const float* vd, const float* vdp,
                       const float* vdm, float channelShare, float neighbourShare, bool first,
                       float* plus, float* minus, float* sym, float* sPlus, float* sMinus,
                       float* sSym);

// Centre-only denominators (vdp = vdm = vd, neighbourShare ½) depend on p alone:
// invPair = 1 / (2 vd + ε), invSym = 1 / (vd + ½ (vd + vd) + ε), once per pixel.
void centreReciprocals(int n, const float* vd, float* invPair, float* invSym);

// addColorDistances with centre-only denominators, from centreReciprocals' planes (same bits).
void addCentreColorDistances(int n, const float* g, const float* gp, const float* gm,
                             const float* vn, const float* vnp, const float* vnm,
                             const float* invPair, const float* invSym, float channelShare,
                             bool first, float* plus, float* minus, float* sym);

// One feature channel's pixel distances (clamped) to p + δ, p − δ and to their mean, added to
// plus / minus / sym, with one denominator set (symmetric: den + neighbourShare (denp + denm)).
// sym may be null (no symmetric distance).
void addFeatureDistances(int n, const float* f, const float* fp, const float* fm, const float* vn,
                         const float* vnp, const float* vnm, const float* den, const float* denp,
                         const float* denm, float neighbourShare, float* plus, float* minus,
                         float* sym);

// dst[i] = Σ_{j = −r … r} src[i + j] (src readable from −r to n + r).
void horizontalBoxSum(int n, const float* src, int r, float* dst);

// dst[i] = Σ_{j = 0 … count − 1} src[i + j · stride] · scaleY · scaleX[i]: a column of row sums
// turned into a box mean.
void verticalBoxMean(int n, const float* src, size_t stride, int count, float scaleY,
                     const float* scaleX, float* dst);

// dst[i] = (inner[i − r0 − 1] + src[i]) + inner[i + r0 + 1]: the box sums of radius 2 r0 + 1
// from those of radius r0 (inner readable from −r0 − 1 to n + r0 + 1), 2 additions a pixel
// instead of 4 r0 + 2.
void widenBoxSum(int n, const float* src, const float* inner, int r0, float* dst);

// verticalBoxMean for `rows` consecutive output rows (rows dstStride apart, scaleY per row) with
// running column sums: each row adds the entering row sum and subtracts the leaving one
// (`running`: n floats of scratch). The sums restart from a full one at every call, so their
// rounding error is bounded by one call's rows and does not grow with the image.
void runningBoxMeans(int n, int rows, const float* src, size_t stride, int count,
                     const float* scaleY, const float* scaleX, float* running, float* dst,
                     size_t dstStride);

// out = min(a, b).
void minWeights(int n, const float* a, const float* b, float* out);

// dst = max(dst, scale · src).
void maxScaled(int n, float scale, const float* src, float* dst);

// w = mask · exp(−max(0, d)).
void maskedWeights(int n, const float* d, const float* mask, float* w);

// Refined weights exp(−max(0, d)) of a patch term for δ and −δ (0 where the mask is 0).
void patchWeights(int n, const float* dPlus, const float* dMinus, const float* dSym,
                  const float* maskPlus, const float* maskMinus, const float* maskSym,
                  float minRefineWeight, float* wPlus, float* wMinus);

// Derivatives (shares 1/3) with respect to g(p) of the pixel distances in which p is a
// *neighbour* within its own patch sums: pair (p − δ, p) → nearPlus; pair (p + δ, p) → nearMinus;
// symmetric distances of p − δ (neighbours p, p − 2δ) and of p + δ (neighbours p + 2δ, p) →
// nearSym. g2m / g2p are the values at p − 2δ / p + 2δ; the masks say which pairs exist.
void nearColorSlopes(int n, const float* g, const float* gp, const float* gm, const float* g2p,
                     const float* g2m, const float* vd, const float* vdp, const float* vdm,
                     const float* vd2p, const float* vd2m, const float* maskPlusPair,
                     const float* maskMinusPair, const float* maskBehind, const float* maskAhead,
                     float* nearPlus, float* nearMinus, float* nearSym);

// One row of an RDFC candidate's running sums (rdfc_candidates.cpp): Σw, max w and Σ w u for
// six data planes (b1 and b2, RGB), the planes `accStride` floats apart.
struct CandidateSums {
  const float* dataPlus[6];   // the data at p + δ
  const float* dataMinus[6];  // the data at p − δ
  float* weightSum;
  float* maxWeight;
  float* acc;
  size_t accStride;
};

// Σw, max w and Σ w u of a candidate whose weights are given (THIRD: the feature weights).
void accumulateCandidate(int n, const float* wPlus, const float* wMinus, const CandidateSums& sums);

// One row of a colour candidate (FIRST, SECOND) for one offset pair ±δ.
struct ColorCandidateRow {
  const float* dist[3];      // patch-mean colour distances for δ, −δ and the symmetric pair
  const float* invCount[3];  // 1 / patch count of each
  const float* mask[3];      // 1 where the pair exists
  const float* featPlus;     // feature weights for δ, −δ
  const float* featMinus;
  // Per channel c of y(p): slopes of the pixel distances (δ, −δ, symmetric) where p is the centre,
  // and where p is a neighbour in its own patch (null when δ lies outside the patch).
  const float* slope[3][3];
  const float* nearSlope[3][3];
  const float* guidePlus[3];  // y_c(p + δ), y_c(p − δ)
  const float* guideMinus[3];
  // Per channel planes, `derivativeStride` floats apart: Σ ∂v, Σ ∂v y(q), ∂(max w).
  float* derivativeSum;
  float* derivativeAcc;
  float* maxDerivative;
  size_t derivativeStride;
};

// Weights v = min(refined colour weight exp(−max(0, D)), feature weight) for δ and −δ, their
// exact derivatives with respect to each channel of y(p) — through the exponential, the
// symmetric refinement a = clamp(ws / (w1 + w2) − 1, 0, 1) and the minimum (one-sided at the
// kinks), following the running maximum — and the candidate's sums, in one pass (the
// per-pixel terms stay in registers instead of a row array each).
void accumulateColorCandidate(int n, const ColorCandidateRow& row, float minRefineWeight,
                              const CandidateSums& sums);

// Σw and max w.
void accumulateWeightSums(int n, const float* wPlus, const float* wMinus, float* weightSum,
                          float* maxWeight);

// acc += wPlus · up + wMinus · um (one data channel at p + δ and p − δ).
void accumulateData(int n, const float* wPlus, const float* wMinus, const float* up,
                    const float* um, float* acc);

}  // namespace chorus::rows
