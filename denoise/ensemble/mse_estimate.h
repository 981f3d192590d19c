#pragma once
// The dual-buffer estimate of the base outputs' error matrix (Zheng et al. 2021, §4). For one
// pixel and colour channel, with noisy half means x^A, x^B and base outputs y_i^A, y_i^B:
//
//   ⟨M⟩^A = y^A y^Aᵀ − x^B (1 y^Aᵀ + y^A 1ᵀ) + x^A x^B 11ᵀ,   ⟨M⟩^B likewise (A ↔ B),
//   ⟨M⟩   = ½(⟨M⟩^A + ⟨M⟩^B).
//
// Because x^B is independent of y^A and E[x^A x^B] = μ², ⟨M⟩^A is unbiased for
// E[(y^A − μ)(y^A − μ)ᵀ], the half-buffer error matrix. Expanding,
//
//   ⟨M⟩ = H + c·11ᵀ,  H = ½(e^A e^Aᵀ + e^B e^Bᵀ),  e^A = y^A − x^B·1,  e^B = y^B − x^A·1,
//   c = −½(x^A − x^B)²,
//
// a positive semi-definite H plus a multiple of 11ᵀ that is constant on the simplex. The
// estimator returns H and c separately: the solver needs only H (better conditioned), the
// estimated MSE of a blend w is wᵀHw + c.
//
// Options:
// - form: one matrix per colour channel (as the reference code: one weight vector per channel)
//   or the sum over the three channels (one weight vector per pixel).
// - windowRadius: accumulate H and c over a (2r+1)² neighbourhood with joint-bilateral weights
//   k(p,q) = exp(−|p−q|²/(2σ_s²) − |n_p−n_q|²/(2σ_n²) − |a_p−a_q|²/(2σ_a²)) from the normal
//   and albedo (not the noisy colour, which would correlate the weights with the residuals),
//   and, with windowSigmaColor σ_z > 0, a colour term exp(−Σ_c (z̄_c(p) − z̄_c(q))² /
//   (2σ_z² (V_c(p) + V_c(q)))) on the mean z̄ of the bases' full runs, V the noisy halves'
//   blurred ½(x^A − x^B)²: a window stops at a shadow edge or a caustic that the features do
//   not show. z̄ barely follows one comparator's noise (the members smooth it away).
//   0 = per pixel, as in the paper. Accumulating keeps the estimate unbiased (up to the
//   normalisation by Σk, which does not change the minimiser) and averages out the noise of
//   x^A, x^B, which otherwise dominates the per-pixel choice (README: evidence).
// - relative: divide each fold's terms by (μ_f² + ε), μ_f = the mean of the finite bases' runs
//   of that fold (y^A, y^B or y^(−k); the oracle: the reference), ε = 0.01, so that the
//   objective targets relMSE instead of MSE. The fold's own runs do not see its comparator;
//   a level from the blended outputs did, and biased the ranking of the bases (z = 9–12 in
//   RelativeTermsAreUnbiasedUpToTheCommonTerm; at 4 spp it weighted RDFC and à-trous nearly
//   alike where the truth gives RDFC 0.85). The comparators' noise is weighted by the folds'
//   mean weight.
// - outlierCap F: before the window, scale each pixel's terms by F / (t + F), t their trace
//   (Σ_i H_ii over the groups) in units of the larger of (mean |x|)² and the 95th percentile
//   of the image's traces (relative terms, --relative's and the prior's: the larger of 1 and
//   their own traces' percentile; at a few samples per pixel they run far above 1, and a unit
//   of 1 scaled most pixels by their own comparator's noise). A typical pixel keeps about its
//   weight; a firefly's terms, whose noise (the cross terms −x^A y_i^B with a huge x^A) would
//   otherwise choose the weights of every pixel within the radius, count about as much as F.
//   The percentile: at a few samples per pixel the comparators' noise alone puts the bright
//   tail of an image far above (mean |x|)², and capping it there made the window's sums count
//   every bright pixel alike instead of by its error (docs/ensemble-quality.md). 0 = off.
// - consistency k: at a pixel, a base whose full-buffer output lies further than
//   k·|y^A − y^B|/2 + 0.1·(mean |x| + |ȳ|) from the mean ȳ of its half-buffer outputs in some
//   channel gets weight 0 (unless every base does). The estimate judges the half-buffer runs;
//   a full run that behaves unlike both (NL-means variants that keep a firefly the half runs
//   removed) is outside what it can see. The pixel still enters its neighbours' windows with
//   every base. 0 = off.
// - plausibility κ (0 = off, else ≥ 1): at a pixel, a base whose own error term
//   d_i = ½ Σ_c (y_i^A − x^B)² + (y_i^B − x^A)² exceeds κ²·(min_j d_j + ½ Σ_c (x^A − x^B)²
//   + Σ_c (0.1·(mean |x| + |x̄|))²) gets weight 0 there. The window and the outlier cap average a
//   base's gross error at one pixel (a bright blob that a filter spread from a light, ringing
//   of a regression next to one) with its neighbours', where it is fine, and the weight filter
//   spreads the neighbours' weights back onto the pixel; a base that is far from both noisy
//   halves, by much more than they differ from each other and than the best base is, is not a
//   denoised estimate there. Each half is also tested on its own, at 2κ: a base whose
//   tA_i = Σ_c (y_i^A − x^B)² exceeds (2κ)²·(min_j tA_j + Σ_c (0.1·(mean |x| + |x^B|))²), or
//   likewise tB_i = Σ_c (y_i^B − x^A)², gets weight 0 too (unless that leaves no base). Where
//   one half holds a firefly, its term is large for every base and swamps d_i, while the other
//   half's term still shows which bases passed the firefly through (NFOR and NL-means variants
//   on 4 spp, README). Applied after the consistency test; as that one, a mask of the solve
//   only.
// - imagePrior α (0 = off): add to each pixel's (windowed) H the image-wide mean Ḡ of the
//   per-pixel terms in relative units (each fold's divided by μ_f² + (mean |x|/2)², so that it does
//   not depend on the unit of radiance), scaled to the same trace on the tangent space {Σv = 0}
//   (the part of H the solve sees) and times α: H + α·(τ(H)/τ(Ḡ))·Ḡ. Shrinkage towards the
//   blend that is best over the whole image: a window holds ~100 pixels whose noisy halves, at
//   a few samples per pixel, cannot rank bases that differ by less than their noise, while the
//   image-wide mean can; where one base is clearly better locally its H still decides. A pixel
//   whose window holds no pixel with its bases gets Ḡ alone. Not applied to the oracle.
// - noisyFallback K (0 = off, else ≥ 1; applied by the ensemble combiner): where even the best
//   base's d_i exceeds K²·(½ Σ_c (x^A − x^B)² + Σ_c (0.1·(mean |x| + |x̄|))²), the result is the
//   noisy full-buffer value. Every base then spread energy into the pixel that neither half
//   shows (a lamp's bulb smeared onto the black pixel beside it: LightsPunctualLamp, 128 spp,
//   rdfc 22 and sbf 3.5 where the reference is 0.03 and all four sub-buffers 0.0001), and no
//   blend of them can be right; the pixel's own samples can. Off by default (issue 25): where
//   the noisy value is the implausible one (a few samples per pixel of a light reached through
//   one bounce: both halves 0, every member lit from the neighbours) it made black speckle, and
//   it lost on the evaluation corpus (docs/ensemble-quality.md).
// Non-finite inputs: a base whose output (any run) is NaN/Inf at a pixel is invalid there (its
// bit in `valid` is 0; the solver gives it weight 0). The pixel still adds the entries of the
// other bases to its neighbours' windows, and each windowed entry is the mean over the pixels
// where both its bases are present (issue 26: one bad member changes nothing where the others
// are fine); the image prior's entries likewise, and its scale is taken over the bases present
// at each pixel. A pixel whose noisy comparators are non-finite adds nothing.
#include <array>
#include <limits>
#include <span>
#include <vector>

#include "denoise/ensemble/ensemble_inputs.h"
#include "denoise/ensemble/ensemble_types.h"
#include "denoise/ensemble/planar_filter.h"

namespace chorus {

enum class MseForm { PerChannel, Summed };

// Which runs the estimate compares with which noisy means ("folds"):
// - Halves: y^A with x^B and y^B with x^A (the paper's dual-buffer estimate): the error of a
//   run on half the samples.
// - Quarters: y^(−k), the run on every quarter but k, with x_k (k = 0 … 3; needs K = 4 and the
//   held-out runs): the error of a run on 3/4 of the samples, closer to the full run's at a
//   few samples per pixel, where members that split their own input (NFOR, RDFC) are much
//   better on the full buffer than on a half. Unbiased for the same reason: y^(−k) does not
//   see quarter k.
// - Extrapolated: 1.5 × the quarters' estimate − 0.5 × the halves' (an error that falls as
//   a + b/s with the share s of the samples, extrapolated from s = ½ and ¾ to 1). Not unbiased
//   for any run's error; may be indefinite (the solver then finds a feasible local minimiser).
// Quarters and Extrapolated fall back to Halves where the inputs have no quarters and held-out
// runs (K = 2 renders, a directory of outputs).
enum class MseEstimate { Halves, Quarters, Extrapolated };
inline const char* estimateName(MseEstimate e) {
  return e == MseEstimate::Halves     ? "halves"
         : e == MseEstimate::Quarters ? "quarters"
                                      : "extrapolated";
}

struct MseOptions {
  MseForm form = MseForm::Summed;
  MseEstimate estimate = MseEstimate::Quarters;
  int windowRadius = 5;
  // The radius the pipeline uses instead where the weights blend the members' full runs and a
  // member splits its own input (optionsForRuns, denoise/pipeline/ensemble.h).
  int fullRunWindowRadius = 15;
  bool relative = false;
  double outlierCap = 30.0;
  double consistency = 4.0;
  double plausibility = 4.0;
  double imagePrior = 0.3;
  double noisyFallback = 0.0;
  double memberFallback = 0.0;
  float windowSigmaSpatial = 0;  // σ_s in pixels; 0 = the window radius
  float windowSigmaNormal = 0.2f;
  float windowSigmaAlbedo = 0.1f;
  // σ of the window's colour term on the members' mean blend, in units of the noisy halves'
  // spread; 0 = features only (the oracle always uses features only).
  float windowSigmaColor = 2.0f;
};

// ⟨M⟩ at one pixel in the objective's units (radiance², or relative), per channel group g
// (3 groups, one per channel, or 1 summed): ⟨M⟩_g = h[g] + constant[g]·11ᵀ.
struct PixelMse {
  int groups = 0;
  std::array<MseMatrix, 3> h;
  std::array<double, 3> constant{};
  BaseMask valid = 0;
};

// ⟨M⟩ for the rows [y0, y1) of the image, stored as float planes (normalised to O(1)).
class MseRows {
 public:
  int y0() const { return y0_; }
  int y1() const { return y1_; }
  void pixel(int x, int y, PixelMse& out) const;
  // Only the diagonal of h (the per-base estimated MSE), for the one-hot combiners.
  double diagonal(int x, int y, int group, int base) const;
  BaseMask valid(int x, int y) const { return valid_[index(x, y)]; }
  // MseEstimator::noBasePlausible at the pixel.
  bool noisyFallback(int x, int y) const { return fallback_[index(x, y)] != 0; }

 private:
  friend class MseEstimator;
  size_t index(int x, int y) const { return size_t(y - y0_) * size_t(width_) + size_t(x); }
  int y0_ = 0, y1_ = 0, width_ = 0, baseCount_ = 0, groups_ = 0, entries_ = 0;
  double unit_ = 1.0;          // stored value × unit = objective units
  std::vector<float> planes_;  // plane (g·(entries + 1) + e), e = packed upper triangle, then c
  std::vector<BaseMask> valid_;
  std::vector<char> fallback_;
};

// Computes ⟨M⟩ for a fixed set of inputs. Holds pointers to the images it was built from (they
// must outlive it); const and thread-safe after construction.
class MseEstimator {
 public:
  // The dual-buffer estimate from the noisy halves (what the ensemble uses).
  MseEstimator(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases,
               const MseOptions& options);
  // The true error matrix of the full-buffer outputs against a reference (for the oracle):
  // H = e eᵀ with e = y − r, c = 0.
  static MseEstimator oracle(const EnsembleGuides& guides,
                             std::span<const BaseOutputs* const> bases, const Image& reference,
                             const MseOptions& options);

  int baseCount() const { return baseCount_; }
  int groups() const { return options_.form == MseForm::PerChannel ? 3 : 1; }
  int width() const { return width_; }
  int height() const { return height_; }
  const MseOptions& options() const { return options_; }

  // ⟨M⟩ for rows [y0, y1) (reads rows y0 − r … y1 + r − 1 of the inputs).
  MseRows rows(int y0, int y1) const;
  // One pixel (computes its row; for tests and tools, not for loops over the image).
  PixelMse at(int x, int y) const;
  // The bases whose outputs are finite at a pixel (index y·width + x).
  BaseMask validAt(size_t pixel) const;
  // validAt without the bases that fail the consistency or plausibility test there: the
  // solver's mask.
  BaseMask solvableAt(size_t pixel) const;
  // True where noisyFallback K is on and even the best finite base's own error term d exceeds
  // K²·(½ Σ_c (x^A − x^B)² + Σ_c (0.1·(mean |x| + |x̄|))²): every base is far from both noisy
  // halves, which agree (see noisyFallback).
  bool noBasePlausible(size_t pixel) const;
  // memberFallback K (0 = off, else ≥ 1): per pixel, the base to use instead of the blend of
  // `weights` (one map per base, 1 or 3 channels), or −1 to keep the blend. Where the blend's
  // own error term d_z = mean over the folds of Σ_c (z^f − x_f)², z^f = Σ_i w_i y_i^f, exceeds
  // K²·(min_i d_i + the comparators' noise + the 10 % floor), the base with the least d_i is
  // used: a safeguard that chooses between the blend and a member, never the noisy value.
  std::vector<int> memberFallbacks(std::span<const Image> weights) const;

 private:
  MseEstimator(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases,
               const MseOptions& options, const Image* reference);
  // Per-pixel (unwindowed) planes for rows [y0, y1); returns per pixel the bases whose entries
  // it holds (finite there; 0: the pixel holds nothing, e.g. a non-finite noisy comparator).
  // relativeEpsilon < 0: absolute units (divided by scale²); else each fold's divided by
  // μ_f² + relativeEpsilon (relativeWeight).
  // capUnit: the outlier cap's unit in the same units (capUnit_ or priorCapUnit_).
  std::vector<BaseMask> pixelTerms(int y0, int y1, std::vector<float>& planes,
                                   double relativeEpsilon, double capUnit) const;
  double priorEpsilon() const;  // the prior's knee, (mean |x| / 2)²
  double objectiveEpsilon() const;
  BaseMask computeValidAt(size_t pixel) const;  // what validAt returns, from the images
  // The mean of the relative per-pixel terms, each entry over the pixels where both its bases
  // are present (empty when no pixel has any); addImagePrior scales it per pixel.
  std::vector<double> imagePriorTerms() const;
  // The row spacing of the image-wide statistics (the prior, typicalTrace).
  int sampleStride() const;
  // The kCapPercentile-th percentile of the per-pixel traces before the cap (every
  // sampleStride-th row; 0 when no pixel has terms): the outlier cap's unit. Absolute terms
  // over scale² (relativeEpsilon < 0), or relative terms as pixelTerms makes them.
  double typicalTrace(double relativeEpsilon) const;
  // One pixel's Σ_i H_ii before the cap: over scale², or relative (each fold by relativeWeight).
  double absoluteTrace(size_t pixel, BaseMask valid) const;
  double relativeTrace(size_t pixel, BaseMask valid, double relativeEpsilon) const;
  // Adds row y's relative per-pixel terms to the prior's sums and their pixel counts.
  void addPriorRow(int y, std::vector<float>& planes, std::vector<double>& sum,
                   std::vector<size_t>& count) const;
  // H += imagePrior · (tangent trace of H) · imagePrior_, per pixel of `rows`.
  void addImagePrior(MseRows& rows) const;
  // One fold of the estimate: every base's run that did not see `comparator`, the noisy mean
  // it is compared with (halves: y^A with x^B, y^B with x^A; quarters: y^(−k) with x_k).
  struct Fold {
    std::array<const float*, kMaxDenoisers> out{};
    const float* comparator = nullptr;
  };
  static constexpr int kMaxFolds = 4;
  bool comparatorsFinite(size_t pixel) const;
  // The estimated variance of a comparator at one value index (pixel·3 + channel), averaged
  // over the folds: ½(x^A − x^B)² for the halves.
  double comparatorNoise(size_t valueIndex) const;
  static double comparatorNoise(const std::vector<Fold>& folds, size_t valueIndex);
  // 1 / (μ_f² + ε) at one value index, μ_f the mean of the fold's runs of the bases in `valid`.
  double relativeWeight(const Fold& fold, BaseMask valid, size_t valueIndex,
                        double relativeEpsilon) const;
  // Per base of a mask at a pixel: each fold's own error term t_f,i = Σ_c (y_i^f − x_f)², and
  // the allowances the tests compare them with.
  struct FoldTerms {
    int folds = 0;
    // t[f][i] for the folds and bases foldTermsAt fills; the rest is left uninitialised (zeroing
    // all of it was a third of foldTermsAt's time).
    std::array<std::array<double, kMaxDenoisers>, kMaxFolds> t;
    std::array<double, kMaxFolds> floor{};  // Σ_c (0.1 (mean |x| + |x_f|))² per comparator
    double floorMean = 0;                   // the same of the comparators' mean
    double noise = 0;                       // Σ_c comparatorNoise (½ Σ_c (x^A − x^B)²)
    double mean(int i) const;               // d_i: the mean over the folds
    struct Least {
      std::array<double, kMaxFolds> fold;
      double mean;
    };
    Least least(BaseMask mask, int baseCount) const;  // least t_f and d over `mask`
  };
  FoldTerms foldTermsAt(size_t pixel, BaseMask mask) const;
  // The solver's mask and the fallback flag at a pixel, from one evaluation of the fold terms.
  struct PixelMasks {
    BaseMask solvable = 0;
    bool noisyFallback = false;
  };
  PixelMasks masksAt(size_t pixel) const;
  // The bases of `mask` that pass the consistency test / the plausibility test at a pixel.
  BaseMask consistentBases(size_t pixel, BaseMask mask) const;
  BaseMask plausibleBases(BaseMask mask, const FoldTerms& terms) const;
  int planeCount() const { return groups() * (entries() + 1); }
  int entries() const { return baseCount_ * (baseCount_ + 1) / 2; }

  MseOptions options_;
  int width_ = 0, height_ = 0, baseCount_ = 0;
  double scale_ = 1.0;  // absolute form: values are divided by scale² (scale = mean |x|)
  // The outlier cap's unit in the objective's terms' units (over scale², or relative with
  // --relative): 1, or the traces' percentile where larger; priorCapUnit_ the same for the
  // prior's relative terms. In relative units the traces of a few-sample image run far above
  // 1, and a unit of 1 weighted most pixels by their own comparator's noise
  // (docs/ensemble-quality.md).
  double capUnit_ = 1.0, priorCapUnit_ = 1.0;
  std::array<const float*, kMaxDenoisers> outFull_{};
  std::vector<Fold> folds_;           // the tests' folds and the estimate's (weight primary)
  std::vector<Fold> secondaryFolds_;  // Extrapolated: the halves (weight secondary)
  double primaryWeight_ = 1.0, secondaryWeight_ = 0.0;
  const float* reference_ = nullptr;  // oracle only
  std::vector<double> imagePrior_;    // imagePriorTerms() (empty: no prior)
  std::vector<BaseMask> validity_;    // validAt per pixel
  PlanarGuides windowGuides_;
  BilateralKernel windowKernel_;
};

}  // namespace chorus
