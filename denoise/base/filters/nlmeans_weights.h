#pragma once
// NL-means weights with dual-buffer variance cancellation (Rousselle, Knaus, Zwicker 2012) — the
// building block shared by NFOR, RDFC and the NL-means denoisers (base-denoisers.md §0).
//
// A weight between a pixel p and a neighbour q = p + δ (δ in the (2r+1)² window) is the minimum
// over one or more *terms*. A term has a guide image g, the variance of the mean of g, V, and
// optionally a separate denominator variance Vd (RDFC's normalising feature variance; else V).
// Per channel c it defines the pixel distance
//
//   d_c(p, q) = [ (g_c(p) − g_c(q))² − α s (V_c(p) + min(V_c(p), V_c(q))) ]
//               / ( ε + k² s (Vd_c(p) + Vd_c(q)) ),
//
// clamped to ≤ distanceClamp. The `min` keeps a bright noisy neighbour from cancelling a real
// difference. A pixel whose guide, V or Vd is not finite (a feature without samples) gets the
// clamp: it matches nothing. The patch distance D_c(p, q) is the mean of d_c(p + o, q + o) over
// the patch offsets o ∈ [−f, f]² with p + o and q + o both inside the image (true count at the
// borders). Channels become weights as `ChannelWeights` says; a weight is exp(−max(0, D)).
//
// Options: Rousselle's symmetric-pair refinement (δ and −δ together, plus the distance from p to
// the mean of its two neighbours), "patchwise" weights (box-filtered over weightBoxRadius after
// exponentiation), a threshold below which weights are 0, and a policy for the centre weight.
//
// Cost: each offset pair ±δ is processed once per tile: per-pixel distance images, a separable
// box filter, exponentiation — O(N (2r+1)²) independent of the patch size f.
#include <limits>
#include <span>
#include <vector>

#include "common/image/image.h"
#include "denoise/base/filters/pixel_rect.h"
#include "denoise/planes/padded_planes.h"

namespace chorus {

// How a multi-channel term turns its per-channel patch distances D_c into weights.
enum class ChannelWeights {
  PerChannel,       // one weight per channel, w_c = exp(−max(0, D_c)) (Tungsten's nlMeans)
  MinOverChannels,  // one weight, min_c exp(−max(0, D_c)) (Tungsten's regression weights)
  AverageDistance,  // one weight, exp(−max(0, mean_c D_c)) (Rousselle's NL-means, RDFC)
};

// One term of the weight. The images are read (copied) when NlMeansWeights is constructed.
struct NlMeansTerm {
  const Image* guide = nullptr;                // g
  const Image* variance = nullptr;             // V: variance of the mean of g, same shape
  const Image* denominatorVariance = nullptr;  // Vd (same shape); null: Vd = V
  int f = 3;                                   // patch radius; 0 = pixel-wise distance
  float k = 0.45f;                             // sensitivity: larger k, larger weights
  float alpha = 1.0f;                          // α: strength of the variance cancellation
  float s = 1.0f;  // variance scale, multiplies V and Vd (2 when g is a half of the input but
                   // V is the whole input's variance of the mean, as in Tungsten's NFOR)
  float epsilon = 1e-10f;      // ε in the denominator
  float distanceClamp = 1e4f;  // d is clamped to at most this (Tungsten: 1e4)
  ChannelWeights channels = ChannelWeights::AverageDistance;
  bool centerOnlyDenominator = false;  // denominator ε + 2 k² s Vd(p) (RDFC's second pass)
  // Symmetric-pair refinement (Rousselle's code): with w1 = w(p, p+δ), w2 = w(p, p−δ) and w_s
  // the weight between p and the mean of both neighbours (variance terms (V(n1) + V(n2)) / 4),
  // a = clamp(w_s / (w1 + w2) − 1, 0, 1), w1 ← a w_s + (1 − a) w1, likewise w2; applied only
  // where both D(p, p±δ) < symmetricDistanceLimit (RDFC: 25). Keeps gradients from flattening.
  bool symmetricRefinement = false;
  float symmetricDistanceLimit = std::numeric_limits<float>::infinity();
};

// Row kernels process whole vectors of this many pixels where their buffers allow: an AVX2
// vector, so that a row of an AVX-512 build ends in at most one half-width vector and no
// scalar tail (divisions bound these kernels; padding further only adds divisions).
inline constexpr int kRowVector = 8;

// The centre weight w(p, p).
enum class CenterWeight {
  Computed,         // the term weights of p with itself (1 unless p's statistics are missing),
                    // at least minCenterWeight (Tungsten: floor 1e-4)
  One,              // always 1 (Rousselle's NL-means)
  MaxOfNeighbours,  // the largest neighbour weight of p, at least minCenterWeight (RDFC: 1e-3);
                    // resolved by the filter, which sees every offset
};

struct NlMeansParams {
  int r = 10;                 // window radius: δ ∈ [−r, r]²
  int weightBoxRadius = 0;    // "patchwise" NL-means: weights box-filtered over this radius
  float weightThreshold = 0;  // weights below this become 0 (Rousselle's NL-means: 0.05)
  CenterWeight center = CenterWeight::Computed;
  float minCenterWeight = 0;
};

// Scratch memory for one thread; reuse it across calls.
struct NlMeansScratch {
  std::vector<float> pixelDistance, patchDistance, boxTmp;
  std::vector<float> termPlus, termMinus, termSymmetric, plus, minus;
};

// Weights of a fixed set of terms on a fixed image size ("commit" at construction: the guides
// are copied into planar form with their variance factors folded in). Thread-safe to use from
// many threads, each with its own scratch.
class NlMeansWeights {
 public:
  // Throws std::invalid_argument when a term has no guide/variance, shapes disagree, or
  // PerChannel terms have different channel counts.
  NlMeansWeights(std::span<const NlMeansTerm> terms, const NlMeansParams& params);
  NlMeansWeights(const NlMeansTerm& term, const NlMeansParams& params)
      : NlMeansWeights(std::span<const NlMeansTerm>(&term, 1), params) {}

  int width() const { return width_; }
  int height() const { return height_; }
  // 1, or the channel count of the PerChannel terms (scalar terms then apply to every channel).
  int weightChannels() const { return weightChannels_; }
  const NlMeansParams& params() const { return params_; }

  // Calls fn(dx, dy) once for every unordered offset pair {δ, −δ}, δ ≠ 0, in a fixed order
  // (δ is the member with dy > 0, or dy = 0 and dx > 0).
  template <typename Fn>
  void forEachOffsetPair(Fn&& fn) const {
    for (int dy = 0; dy <= params_.r; ++dy)
      for (int dx = dy == 0 ? 1 : -params_.r; dx <= params_.r; ++dx) fn(dx, dy);
  }

  // w_δ(p) into `plus` and w_−δ(p) into `minus` for every p of `tile`, δ ≠ 0. Layout:
  // weightChannels() planes of tile.area() values, row-major within the tile. The weight is 0
  // where p + δ (resp. p − δ) is outside the image, and where p is (the tile may extend past
  // the image).
  void offsetPair(const PixelRect& tile, int dx, int dy, NlMeansScratch& scratch, float* plus,
                  float* minus) const;

  // The centre weight w(p, p) for every p of `tile` under params().center (same layout).
  // MaxOfNeighbours yields minCenterWeight here; nlMeansFilter resolves it.
  void center(const PixelRect& tile, NlMeansScratch& scratch, float* out) const;

  // Patch distances of one term before channels are combined: D_c(p, p + δ) for p in `region`,
  // which must lie inside neighbourInside(width, height, dx, dy). Writes one plane per guide
  // channel (one plane, the channel mean, for AverageDistance) of region.area() values.
  void patchDistance(int term, const PixelRect& region, int dx, int dy, NlMeansScratch& scratch,
                     float* out) const;

  // Like patchDistance, but the distance of the symmetric-pair refinement: from p to the mean
  // of p + δ and p − δ (variance terms (V(p+δ) + V(p−δ)) / 4). `region` must lie inside both
  // neighbourInside(width, height, ±dx, ±dy); the patch mean counts the pixels whose two
  // neighbours exist. (RDFC's SURE derivative perturbs these distances.)
  void symmetricPatchDistance(int term, const PixelRect& region, int dx, int dy,
                              NlMeansScratch& scratch, float* out) const;

  // How many planes patchDistance writes for a term.
  int distanceChannels(int term) const;

 private:
  struct PreparedTerm {
    int f = 0;
    ChannelWeights channels = ChannelWeights::AverageDistance;
    float epsilon = 0, distanceClamp = 0;
    bool centerOnlyDenominator = false, symmetric = false;
    float refineMinWeight = 0;  // exp(−symmetricDistanceLimit)
    int guideChannels = 0;
    // Planes c: g (NaN where g, V or Vd is not finite); C + c: α s V; 2C + c: k² s Vd. Rows
    // have a margin of kRowVector zeros, so that row kernels may run kRowVector − 1 pixels
    // past a row's end.
    PaddedPlanes planes;
    const float* guideRow(int c, int y) const { return row(c, y); }
    const float* numRow(int c, int y) const { return row(guideChannels + c, y); }
    const float* denRow(int c, int y) const { return row(2 * guideChannels + c, y); }
    const float* row(int plane, int y) const { return planes.plane(plane) + planes.index(0, y); }
  };

  // Per-pixel distances d_c of one row segment [x0, x0 + w) × {y} (stored, or added to `out`
  // when `accumulate`), then zeros up to wVector ≥ w. With `symmetric`, the distance to the
  // mean of p + δ and p − δ.
  static void distanceRow(const PreparedTerm& t, int c, int y, int x0, int w, int wVector, int dx,
                          int dy, bool accumulate, bool symmetric, float* out);
  // Per-pixel distances of term t over rect e for offset (dx, dy): one plane per channel, or
  // their mean when `average`.
  void pixelDistances(const PreparedTerm& t, const PixelRect& e, int dx, int dy, bool average,
                      bool symmetric, float* out) const;
  // Patch distances over `region` (see patchDistance), symmetric variant included.
  void termPatchDistance(const PreparedTerm& t, const PixelRect& region, int dx, int dy,
                         bool symmetric, NlMeansScratch& scratch, float* out) const;
  // Weights (weightChannels planes) of term t over `region` from its patch distances.
  void termWeights(const PreparedTerm& t, const float* distance, size_t area, float* out) const;
  // The combined weights of every term over `region` for one offset (no refinement).
  void combinedWeights(const PixelRect& region, int dx, int dy, NlMeansScratch& scratch,
                       float* out) const;
  // The weights of one offset for one term without refinement or patchwise box, all stages in
  // one sweep over the rows (the row means of the last 2f + 1 rows kept in a ring): the same
  // float operations in the same order as the general path, so bit-identical to it.
  void fusedOffsetWeights(const PreparedTerm& t, const PixelRect& tile, int dx, int dy,
                          NlMeansScratch& scratch, float* out) const;
  // Patchwise box filter, threshold and copy of the tile part of weights over `region`.
  void finishWeights(float* weights, const PixelRect& region, const PixelRect& tile,
                     NlMeansScratch& scratch, float* out) const;

  int width_ = 0, height_ = 0, weightChannels_ = 1;
  NlMeansParams params_;
  std::vector<PreparedTerm> terms_;
  bool anySymmetric_ = false;
  bool fused_ = false;  // fusedOffsetWeights applies
};

}  // namespace chorus
