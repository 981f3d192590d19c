#pragma once
// NL-means filtering with precomputed weight machinery (nlmeans_weights.h):
//   out(p) = Σ_δ w_δ(p) u(p + δ) / Σ_δ w_δ(p)   over the (2r+1)² window clipped to the image.
// Per-channel weights apply channel by channel (data must then have weightChannels()
// channels); a scalar weight applies to every channel of the data. Tiles run in parallel (TBB);
// each output pixel is summed by one task in a fixed order, so results do not depend on the
// thread count.
#include <span>
#include <vector>

#include "common/image/image.h"
#include "denoise/base/filters/nlmeans_weights.h"

namespace chorus {

struct NlMeansFilterResult {
  std::vector<Image> filtered;  // one per data image, same shape as it
  Image weightSum;              // Σ_δ w_δ(p), centre included (weightChannels() channels)
  Image centerWeight;           // w(p, p) as used (weightChannels() channels)
};

// Filters several images of the weights' size with the same weights (e.g. both buffers of a
// dual-buffer pair). A pixel whose weights sum to 0 keeps its own value. Throws
// std::invalid_argument on a size or channel mismatch.
NlMeansFilterResult nlMeansFilterAll(std::span<const Image* const> data,
                                     const NlMeansWeights& weights);

Image nlMeansFilter(const Image& data, const NlMeansWeights& weights);

// One-term convenience: NL-means of `data` with the weights of `term` (guide, variance, f, k…).
Image nlMeans(const Image& data, const NlMeansTerm& term, const NlMeansParams& params);

}  // namespace chorus
