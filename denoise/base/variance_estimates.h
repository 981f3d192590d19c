#pragma once
// Per-pixel variances of the mean that the dual-buffer denoisers feed into their NL-means
// distances, with the two-buffer fallback where a buffer's own estimate does not exist.
//
// A buffer's variance of the mean is M2 / (n (n − 1)): with n = 1 (a quarter at 4 spp) it is 0
// by convention but actually unknown, and a zero variance would make every NL-means distance to
// that pixel huge. There we fall back to the dual-buffer identity (base-denoisers.md §0): halves
// X1, X2 of n1, n2 samples have E[(X1 − X2)²] = σ² (n1 + n2) / (n1 n2), so (X1 − X2)² · n2 /
// (n1 + n2) estimates X1's variance of the mean and (X1 − X2)² · n1 n2 / (n1 + n2)² that of the
// whole (½ and ¼ for equal counts, and where no counts are recorded; a held-out input's halves
// hold one and two quarters). The estimate is box-smoothed (5×5) because a single squared
// difference is very noisy. NaN (no sample of a feature in another renderer's buffers) is
// passed through: the NL-means machinery treats it as "matches nothing".
#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus {

inline constexpr int kVarianceFallbackRadius = 2;
// The neighbourhood of spatialVarianceWhereOneSample: 3 × 3 (5 × 5 was as good on the previews
// at 1-3 spp and took 1.1 s more at 512², 1 spp).
inline constexpr int kSpatialVarianceRadius = 1;

// Which variance of the mean the two-buffer estimate is for.
enum class TwoBufferTarget { Whole, FirstHalf, SecondHalf };

// The factor of (X1 − X2)² whose expectation is the target's variance of the mean, for halves of
// n1, n2 > 0 samples (above).
double twoBufferShare(double n1, double n2, TwoBufferTarget target);

// The two-buffer estimate (X1 − X2)² × twoBufferShare, box-smoothed;
// finite wherever X1, X2 are. Equal counts where the halves have none recorded.
Image twoBufferVariance(const SubBuffer& h1, const SubBuffer& h2, Quantity q,
                        TwoBufferTarget target);

// Variance of the mean of input.whole's quantity q; where the whole has fewer than 2 samples,
// the smoothed two-buffer estimate (needs input.halves).
Image wholeVarianceOfMean(const DenoiseInput& input, Quantity q);

// Variance of the mean of half `which` (0 or 1); where that half has fewer than 2 samples, the
// smoothed two-buffer estimate.
Image halfVarianceOfMean(const DenoiseInput& input, int which, Quantity q);

// `variance` (of buffer's quantity q) where a pixel has 2 samples or more; where it has one
// (a 1-spp render: variance 0 recorded, nothing to compare it with), the spread of the sampled
// means within kSpatialVarianceRadius, (1.4826 × their median absolute deviation)²: SVGF's
// spatial estimate, made robust so that a dark neighbourhood's few bright samples do not widen
// it (docs/members/sbf-atrous-bilateral.md). It holds the signal's own variation too, an
// overestimate at edges, where a feature-guided filter stops anyway. `variance` itself without
// sample counts.
Image spatialVarianceWhereOneSample(const SubBuffer& buffer, Quantity q, const Image& variance);
// Whether some pixel of `buffer` holds exactly one sample (false without sample counts): where
// none does (every run from 4 spp on), spatialVarianceWhereOneSample returns `variance` as it is.
bool hasOneSamplePixels(const SubBuffer& buffer);

}  // namespace chorus
