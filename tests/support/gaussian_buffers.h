#pragma once
// Denoiser inputs whose colour noise satisfies SURE's assumptions exactly: a known truth plus
// independent Gaussian noise of known variance in each of two halves. Features are copied from
// another buffer (e.g. the synthetic scene's), identical in both halves.
#include <cstdint>

#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus::test {

// whole.color = (half1 + half2) / 2 with half_k = truth + N(0, 2 σ²) per pixel and channel, so the
// whole mean has variance σ² = (sigma(x, y, c))², which is stored as its varianceOfMean (halves:
// 2 σ²). Features (means and variances) and sample counts come from `features` for all three.
DenoiseInput gaussianHalves(const Image& truth, const Image& sigma, const SubBuffer& features,
                            uint32_t seed);

// Multiplies the recorded colour variances of the whole and the halves by `factor`: what a
// stratified sampler's sample variances look like against the noise the means actually carry
// (variance_calibration.h).
void overstateColorVariances(DenoiseInput& input, float factor);

// Detail that the features do not show (a white surface whose shading varies from pixel to
// pixel without repeating): 0.5 ± amplitude per pixel, σ 0.02 for the whole.
struct TruthAndSigma {
  Image truth, sigma;
};
TruthAndSigma unrepeatedDetail(int width, int height, float amplitude);

// unrepeatedDetail (amplitude 0.04: ±2σ) through gaussianHalves on flatFeatures with `samples`
// per pixel, the recorded colour variances overstated `factor` times: stratified samples at a
// high count against the members that believe their recorded variance.
struct OverstatedDetail {
  TruthAndSigma scene;
  DenoiseInput input;
};
OverstatedDetail overstatedDetail(int size, float samples, float factor, uint32_t seed);

// Halves of n1 and n2 samples of i.i.d. Gaussian noise (per-sample σ `sigma`) around 0.5 on
// flatFeatures of size × size, the whole their count-weighted mean, with exact recorded variances
// σ²/n, except that a buffer of fewer than 2 samples records 0 (M2 / (n (n − 1)) is undefined),
// as the film does.
DenoiseInput unequalHalves(int size, float n1, float n2, float sigma, uint32_t seed);

// Features of one flat, featureless surface: albedo 0.5, normal +z, depth 2, visibility 1, and
// `samples` samples per pixel.
SubBuffer flatFeatures(int width, int height, float samples);

// A small highlight on a wall that its features do not show (the members' highlight tests): a
// 64 × 64 wall of 0.1 (σ 0.05) with pixels [x0, x0 + 2] × [y0, y0 + 1] at 1000 (σ 500).
struct HighlightOnWall {
  int x0, y0;
  Image truth, sigma;

  bool inHighlight(int x, int y) const { return x >= x0 && x <= x0 + 2 && y >= y0 && y <= y0 + 1; }
  // Squared error of `image` over the wall within 2 pixels of the highlight (near) or beyond 8.
  double wallError(const Image& image, bool near) const;
};
HighlightOnWall highlightOnWall(int x0, int y0);

}  // namespace chorus::test
