#pragma once
// A procedural test scene with known ground truth, rendered into SampleBuffers by simulating
// Monte Carlo samples: every sample lands at a uniform random position inside its pixel,
// records the exact features there (albedo, normal, depth, visibility) and a colour equal to
// the exact radiance there times a random factor of mean 1 (exponential, i.e. relative
// per-sample standard deviation 1, the same factor for all three channels as for a white path
// throughput). Pixels that straddle an edge therefore get feature variance, as in a renderer.
//
// The scene, in coordinates u = x / width, v = y / height (so it scales with the resolution):
//   - a background plane whose albedo changes at u = 0.5 (orange | blue) with a band of
//     black/white albedo stripes (period 1/12 of the width) for v > 0.8, whose depth rises
//     linearly with v, and whose normal changes along a diagonal crease (a shading edge with
//     no albedo edge);
//   - a sphere (yellow albedo, smooth normals, closer depth) centred at (0.62, 0.4), radius 0.2;
//   - one directional light plus ambient: radiance = albedo × (E max(0, n·l) + ambient);
//     visibility = 1 where n·l > 0.
// Ground truth is the pixel integral of the radiance (adaptive supersampling: 4×4, or 16×16 in
// pixels that straddle an edge), times the mean of the noise factor.
//
// Used by the denoiser tests and by tools/bench (which compiles this file directly): it has no
// GoogleTest dependency.
#include <array>
#include <cstdint>
#include <optional>

#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus::test {

struct SyntheticSceneOptions {
  int width = 64;
  int height = 64;
  int subBuffers = 4;           // K independent sub-buffers
  int samplesPerSubBuffer = 4;  // so the full buffer has subBuffers × this samples per pixel
  uint32_t seed = 1;
  // Replaces the shaded radiance by this constant colour, noise-free (features unchanged):
  // for "a constant image stays constant" / "a black image stays black".
  std::optional<std::array<float, 3>> constantColor;
  // With this probability a colour sample is multiplied by fireflyScale (rare, huge samples as
  // from caustic paths). The ground truth includes their expected contribution.
  float fireflyProbability = 0.0f;
  float fireflyScale = 200.0f;
  // Standard deviation of zero-mean Gaussian noise added to every albedo and normal sample
  // (as from depth of field or rough surfaces); 0 = exact features.
  float featureNoise = 0.0f;
  // A pixel counts as "near an edge" when a pixel within this Chebyshev radius straddles an
  // albedo, normal or object edge.
  int edgeRadius = 1;
};

struct SyntheticScene {
  SampleBuffers buffers;        // K sub-buffers, equal sample counts
  Image truth;                  // RGB: expected colour of every pixel (the denoisers' target)
  Image albedo, normal, depth;  // expected features per pixel (3, 3, 1 channels)
  Image edgeMask;               // 1 channel: 1 near a feature edge (see edgeRadius), else 0
  int edgePixelCount = 0;       // pixels with edgeMask = 1

  // The full buffer as a denoiser input (halves A/B when K is even).
  DenoiseInput fullInput() const { return buffers.input(BufferPart::Full); }
};

// Deterministic for given options (independent of the thread count).
SyntheticScene makeSyntheticScene(const SyntheticSceneOptions& options = {});

// The mean of (x − r)² / (r² + ε) over the pixels where mask > 0.5 (all channels), i.e.
// relMSE restricted to a region; NaN when the mask is empty.
double maskedRelMse(const Image& image, const Image& reference, const Image& mask,
                    double epsilon = 0.01);

}  // namespace chorus::test
