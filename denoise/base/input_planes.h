#pragma once
// Sanitised planar views of a SubBuffer for the filters: NaN/Inf never enter a filter, and
// "no sample" is turned into "unknown" in a way each filter can handle.
#include <algorithm>
#include <cmath>

#include "denoise/buffers/sample_buffers.h"
#include "denoise/planes/planar_image.h"

namespace chorus {

// Variance used for a feature whose variance is NaN/Inf (a pixel where the feature had no
// sample, as in Tungsten's buffers): so large that the feature carries no weight there.
inline constexpr float kUnknownVariance = 1e30f;

// Colour mean with non-finite values replaced by 0.
PlanarImage sanitizedMean(const MeanVariance& quantity);

// Radiance beyond this is treated as this, so that squared differences stay finite in float.
inline constexpr float kMaxFilterMagnitude = 1e12f;
// A value clamped to ±kMaxFilterMagnitude, non-finite → 0.
inline float clampedFinite(float v) {
  return std::isfinite(v) ? std::clamp(v, -kMaxFilterMagnitude, kMaxFilterMagnitude) : 0.0f;
}
// An image with every value clamped by clampedFinite.
Image clampedFinite(const Image& image);
// Variance of the mean with non-finite or negative values replaced by 0 (colour: "noise-free").
PlanarImage sanitizedVarianceOfMean(const Image& varianceOfMean);

// Per-sample variance of a feature, M2 / (n − 1) = varianceOfMean × n (Li et al. 2012 use the
// spread of the samples, not of the mean). n < 2 has varianceOfMean = 0 and gives 0; a pixel
// with sampleCount 0 ("unknown", e.g. Tungsten data without meta.json) keeps varianceOfMean
// (as if n = 1), which under-estimates and so keeps edges sharper rather than blurring them.
// NaN/Inf (no sample of the feature) give kUnknownVariance.
PlanarImage perSampleVariance(const MeanVariance& feature, const Image& sampleCount);

// The largest finite depth of the buffer (≤ 0 or none → 1), used to normalise depth to [0, 1].
float maxFiniteDepth(const Image& depth);

}  // namespace chorus
