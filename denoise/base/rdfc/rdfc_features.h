#pragma once
// RDFC's features and their prefiltering (Rousselle, Manzi, Zwicker 2013; base-denoisers.md §3).
//
// Features, each mapped as in the authors' release: normal → (n + 1) / 2; albedo divided by
// max(1, largest channel) (the release divides every sample, we divide the buffer means); depth
// in place of world position (our buffers have no position), its τ scaled by maxDepth²;
// direct-light visibility. The release's "caustic" feature is constant 1 and omitted.
//
// Prefilter, per feature: NL-means of the two buffers f1, f2 with the same weights, guided by
// their mean with the variance rescaled as for colour (Box21, buffer_variance.h), r = 5, f = 3,
// k = 1, weights box-filtered with radius 2 ("patchwise"), symmetric refinement, centre weight =
// largest neighbour weight. f̃ = (f̃1 + f̃2) / 2, Var_f = (f̃1 − f̃2)² / 4 smoothed by the 3-tap
// [e⁻², 1, e⁻²], G_f = squared gradient of f̃. Pixels where the feature has no statistics (NaN
// mean or variance) are left out of the prefilter and are neutral in the range terms
// (variance kNeutralVariance).
#include <string>
#include <vector>

#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus {

struct RdfcPrefilterParams {
  int r = 5;                    // window radius
  int f = 3;                    // patch radius
  float k = 1.0f;               // NL-means sensitivity
  int weightBoxRadius = 2;      // "patchwise": weights box-filtered over f − 1
  bool rescaleVariance = true;  // Box21 rescaling for correlated samples (false: σ² as is)
};

struct RdfcFeature {
  std::string name;            // "normal", "albedo", "depth", "visibility"
  Image value;                 // f̃ (0 where unknown)
  Image variance;              // Var_f (kNeutralVariance where unknown)
  Image gradient;              // G_f, squared gradient of f̃ (0 where unknown)
  float tauScale = 1.0f;       // τ multiplier: maxDepth² for depth, 1 otherwise
  std::vector<uint8_t> known;  // per pixel: 1 if the feature has statistics there

  // RDFC's normalising variance Vn = max(Var_f, max(G_f, τ · tauScale)); kNeutralVariance where
  // unknown.
  Image normalizingVariance(float tau) const;
};

// Mapped, prefiltered features of `input` (which must have halves). Deterministic for any thread
// count; all outputs finite.
std::vector<RdfcFeature> prefilterRdfcFeatures(const DenoiseInput& input,
                                               const RdfcPrefilterParams& params);

}  // namespace chorus
