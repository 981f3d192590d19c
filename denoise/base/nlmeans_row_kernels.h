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
// to g(p) (unclamped), written to sPlus / sMinus / sSym.
void addColorDistances(int n, const float* g, const float* gp, const float* gm, const float* vn,
                       const float* vnp, const float* vnm, const float* vd, const float* vdp,
                       const float* vdm, float channelShare, float neighbourShare, float* plus,
                       float* minus, float* sym, float* sPlus, float* sMinus, float* sSym);

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

// Per-pixel quantities of one colour candidate's weights for one offset pair ±δ, kept for the
// derivative pass (row arrays of n values each).
struct ColorWeightTerms {
  float *w1, *w2, *ws;  // colour weights exp(−max(0, D)) for δ, −δ and the symmetric pair
  float *k1, *k2, *ks;  // ∂w / ∂D · (1 / patch count): −w where 0 < D < 87, else 0
  float *a, *sum, *invSum2;  // refinement factor, w1 + w2, 1 / (w1 + w2)² where a ∈ (0, 1)
  float *pass1, *pass2;      // 1 where the colour weight is below the feature weight
  float *pick1, *pick2;      // 1 where this weight becomes the running maximum
};

// Weights v = min(refined colour weight, feature weight) for δ and −δ into vPlus / vMinus, and
// the terms of their derivatives (one output array per ColorWeightTerms field: separate
// restrict-qualified arguments, which GCC needs to vectorise the loop). maxWeight is the running
// maximum before this offset.
void colorCandidateWeights(int n, const float* dPlus, const float* dMinus, const float* dSym,
                           const float* invCountPlus, const float* invCountMinus,
                           const float* invCountSym, const float* maskPlus, const float* maskMinus,
                           const float* maskSym, float minRefineWeight, const float* fPlus,
                           const float* fMinus, const float* maxWeight, float* vPlus, float* vMinus,
                           float* w1, float* w2, float* ws, float* k1, float* k2, float* ks,
                           float* a, float* sum, float* invSum2, float* pass1, float* pass2,
                           float* pick1, float* pick2);
inline void colorCandidateWeights(int n, const float* dPlus, const float* dMinus, const float* dSym,
                                  const float* invCountPlus, const float* invCountMinus,
                                  const float* invCountSym, const float* maskPlus,
                                  const float* maskMinus, const float* maskSym,
                                  float minRefineWeight, const float* fPlus, const float* fMinus,
                                  const float* maxWeight, float* vPlus, float* vMinus,
                                  const ColorWeightTerms& t) {
  colorCandidateWeights(n, dPlus, dMinus, dSym, invCountPlus, invCountMinus, invCountSym, maskPlus,
                        maskMinus, maskSym, minRefineWeight, fPlus, fMinus, maxWeight, vPlus,
                        vMinus, t.w1, t.w2, t.ws, t.k1, t.k2, t.ks, t.a, t.sum, t.invSum2, t.pass1,
                        t.pass2, t.pick1, t.pick2);
}

// Exact derivative of those weights with respect to one channel of y(p), from the slopes of the
// channel's distances: through exp(−max(0, D)), the symmetric refinement
// a = clamp(ws / (w1 + w2) − 1, 0, 1) and the minimum (one-sided at the kinks). Adds Σ ∂v and
// Σ ∂v y(p ± δ) and follows the derivative of the running maximum.
void accumulateColorDerivative(int n, const float* w1, const float* w2, const float* ws,
                               const float* k1, const float* k2, const float* ks, const float* a,
                               const float* sum, const float* invSum2, const float* pass1,
                               const float* pass2, const float* pick1, const float* pick2,
                               const float* slopePlus, const float* slopeMinus,
                               const float* slopeSym, const float* gPlus, const float* gMinus,
                               float* derivativeSum, float* derivativeAcc, float* maxDerivative);
inline void accumulateColorDerivative(int n, const ColorWeightTerms& t, const float* slopePlus,
                                      const float* slopeMinus, const float* slopeSym,
                                      const float* gPlus, const float* gMinus, float* derivativeSum,
                                      float* derivativeAcc, float* maxDerivative) {
  accumulateColorDerivative(n, t.w1, t.w2, t.ws, t.k1, t.k2, t.ks, t.a, t.sum, t.invSum2, t.pass1,
                            t.pass2, t.pick1, t.pick2, slopePlus, slopeMinus, slopeSym, gPlus,
                            gMinus, derivativeSum, derivativeAcc, maxDerivative);
}

// Σw and max w.
void accumulateWeightSums(int n, const float* wPlus, const float* wMinus, float* weightSum,
                          float* maxWeight);

// acc += wPlus · up + wMinus · um (one data channel at p + δ and p − δ).
void accumulateData(int n, const float* wPlus, const float* wMinus, const float* up,
                    const float* um, float* acc);

}  // namespace chorus::rows
