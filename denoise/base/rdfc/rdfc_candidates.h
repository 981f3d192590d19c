#pragma once
// RDFC's three candidate filters with their SURE error estimates (Rousselle, Manzi, Zwicker
// 2013; base-denoisers.md §3), computed in one pass over the window offsets.
//
// Every candidate filters both buffers b1, b2 with the same weights, w(p, q) = min over a colour
// term and one term per feature:
//   colour  — NL-means patch distance (§0) on the guide y = (b1 + b2)/2 with variance V, α = 1,
//             ε = 1e-10, channel average, denominator k_c² (V(p) + V(q)), patch radius f;
//   feature — pixel-wise distance on f̃_j with numerator variance Var_j and denominator
//             k_f² (Vn_j(p) + Vn_j(q)), Vn_j = max(Var_j, max(G_j, τ)), channel average;
// each term with Rousselle's symmetric-pair refinement (distance limit 25), weight
// exp(−max(0, D)), window radius r, centre weight = largest neighbour weight (at least 1e-3).
//   FIRST: k_c = 0.45, f = 1, k_f = 0.6, τ = 1e-3;  SECOND: k_c = 0.45, f = 3, same features;
//   THIRD: no colour term, k_f = 0.6, τ = 1e-4.
// FIRST and SECOND share their feature weights and their per-pixel colour distances (only the
// patch box differs), which is why the three are computed together.
//
// SURE per pixel, channel mean: (F − y)² + 2 V ∂F/∂y − V (sure.h). ∂F_c/∂y_c(p) is exact: the
// release takes a finite difference (y(p) × 1.01, weights of p recomputed); we take its h → 0
// limit, differentiating p's weights through the patch distances — where p is the centre and,
// for offsets within the patch, a neighbour — the exponential, the symmetric refinement, the
// minimum with the feature weights and the centre weight. Each channel on its own: the release
// moves all three at once, which adds cross-channel terms to the divergence (a measurable SURE
// bias for FIRST). If any channel's value falls outside [0, 1], all three use w_centre / Σw
// (the release's rule, exact for THIRD, whose weights do not depend on y).
#include <array>
#include <vector>

#include "common/image/image.h"
#include "denoise/base/rdfc/rdfc_features.h"

namespace chorus {

// A pixel's own weight in every RDFC filter is at least this (the release's WEIGHT_EPSILON).
inline constexpr float kRdfcMinCenterWeight = 1e-3f;

struct RdfcCandidateParams {
  int r = 10;                    // window radius of all three candidates
  float kc = 0.45f;              // k_c of FIRST and SECOND
  int fFirst = 1;                // colour patch radius of FIRST (3×3)
  int fSecond = 3;               // colour patch radius of SECOND (7×7)
  float kf = 0.6f;               // k_f of all three
  float tauFirstSecond = 1e-3f;  // τ of FIRST and SECOND (depth: τ · maxDepth²)
  float tauThird = 1e-4f;        // τ of THIRD
  // The release's rule: where any channel's ∂F/∂y falls outside [0, 1], all three use
  // w_centre / Σw. (Off: the exact derivative everywhere, for testing SURE itself.)
  bool derivativeFallback = true;
};

struct RdfcCandidate {
  Image buffer1, buffer2;  // the filtered buffers (RGB)
  Image mean;              // F = (buffer1 + buffer2) / 2
  Image derivative;        // ∂F_c/∂y_c per channel
  Image sure;              // 1 channel: SURE averaged over RGB
};

// The candidates FIRST, SECOND, THIRD, in that order. buffer1/buffer2: the two buffers' colour
// (finite); colorVariance: V, the variance of the mean of (b1 + b2)/2 (finite, ≥ 0); features as
// from prefilterRdfcFeatures (may be empty). Deterministic for any thread count.
std::array<RdfcCandidate, 3> rdfcCandidates(const Image& buffer1, const Image& buffer2,
                                            const Image& colorVariance,
                                            const std::vector<RdfcFeature>& features,
                                            const RdfcCandidateParams& params);

}  // namespace chorus
