#pragma once
// NL-means filtering whose weight is the minimum over several independently configured weight
// sets (nlmeans_weights.h):  w(p, q) = min_k w_k(p, q),  out(p) = Σ_q w u(q) / Σ_q w.
// Each set keeps its own options, so e.g. RDFC's colour weights can be box-filtered
// ("patchwise") while its feature weights are not — one NlMeansWeights with several terms would
// box-filter the minimum and blur the feature edges. The centre weight is the largest neighbour
// weight of the pixel, at least minCenterWeight (RDFC). Tiles run in parallel (TBB); every output
// pixel is summed by one task in a fixed order, so results do not depend on the thread count.
#include <span>
#include <vector>

#include "denoise/base/filters/nlmeans_weights.h"
#include "denoise/image/image.h"

namespace chorus {

// Filters every data image (any channel count, the weights' size) with the same weights. All
// weight sets must have the same size, one weight channel, and the same window radius r.
// Throws std::invalid_argument otherwise.
std::vector<Image> nlMeansFilterMin(std::span<const Image* const> data,
                                    std::span<const NlMeansWeights* const> weights,
                                    float minCenterWeight);

}  // namespace chorus
