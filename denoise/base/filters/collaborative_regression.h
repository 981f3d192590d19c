#pragma once
// Collaborative first-order regression (Bitterli et al. 2016, §5.2; Tungsten's
// collaborativeRegression). For every pixel p, with window Ω_p = the (2r+1)² pixels around p
// clipped to the image and scalar NL-means weights w_q = w(p, q):
//   design row x_q = [1, q_x − p_x, q_y − p_y, f_1(q) − f_1(p), …, f_m(q) − f_m(p)],
//   β_p = argmin Σ_q w_q |x_qᵀ β − u(q)|²   (rank-revealing, gram_solver.h),
// then every q ∈ Ω_p receives the prediction x_qᵀ β_p with weight w_q:
//   out(q) = Σ_p w_pq x_qᵀ β_p / Σ_p w_pq.
// Tiles of 32×32 centres run in parallel (TBB); their accumulators are gathered in a fixed
// order, so the result does not depend on the thread count. Within a tile, sixteen consecutive
// centres of a row are regressed together, one per vector lane (AVX-512, AVX2 and baseline
// builds give the same bits).
#include <span>
#include <vector>

#include "common/image/image.h"
#include "denoise/base/filters/gram_solver.h"
#include "denoise/base/filters/nlmeans_weights.h"

namespace chorus {

// How the Gram sums are blocked in vector registers: for this CPU's vector width by default
// (AVX-512: Wide; otherwise Narrow). Both give the same bits (tests run both).
enum class GramSumBlocking { ForThisCpu, Wide, Narrow };

// `image`: the data u (≤ 4 channels); `features`: m channels (m ≤ 21), one per regressor,
// non-finite values are treated as 0; `weights`: scalar weights of the image's size, whose
// window radius r is the regression window. Throws std::invalid_argument on mismatches.
Image collaborativeRegression(const Image& image, const Image& features,
                              const NlMeansWeights& weights, const GramTolerances& tolerances = {},
                              GramSumBlocking blocking = GramSumBlocking::ForThisCpu);

inline constexpr int kMaxWeightPower = 16;

// The regressions with weights w^p for every p of `powers` (1 ≤ p ≤ kMaxWeightPower), from one
// evaluation of `weights`: NL-means distances scale with 1 / k², so w^p is the weight of the
// bandwidth k / √p (NFOR's k = 0.5 from k = 1: p = 4) — exactly, except where ε or the distance
// clamp matter, i.e. where the weights are (numerically) 0 anyway. Underflowing powers are 0, the
// centre keeps the minCenterWeight floor. One output per power.
std::vector<Image> collaborativeRegressions(const Image& image, const Image& features,
                                            const NlMeansWeights& weights,
                                            std::span<const int> powers,
                                            const GramTolerances& tolerances = {},
                                            GramSumBlocking blocking = GramSumBlocking::ForThisCpu);

}  // namespace chorus
