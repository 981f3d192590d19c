#pragma once
// The colour's variance of the mean at the level the samples actually vary.
//
// chorus's sampler stratifies a pixel's samples (Owen-scrambled Sobol, docs/renderer.md), so the
// sample variance / n that a buffer records overestimates the variance of its mean — the more,
// the more samples and the smoother the integrand over the pixel: on the evaluation corpus by
// 1.0–1.1× (lamp) to 1.6–2.4× (flight-helmet-white) at 16–256 spp. Two independent halves'
// squared difference has the right level but is one noisy value per pixel. So, as RDFC does for
// its own variance (../shared/docs/base-denoisers.md §3), the sample variance keeps its
// per-pixel structure and takes the halves' level over a box of radius R: per pixel and channel
// the factor is
//   Box_R((h1 − h2)² · n1 n2 / (n1 + n2)²) / Box_R(V_whole),
// where (h1 − h2)² n1 n2 / (n1 + n2)² estimates the variance of the whole's mean for halves of
// n1 and n2 samples (the held-out inputs' halves hold a quarter and a half; equal counts where
// none are recorded). The halves' own variances take the same factor.
#include <limits>

#include "common/image/image.h"
#include "denoise/buffers/sample_buffers.h"

namespace chorus {

// The largest box radius a member's calibrate=R option accepts.
inline constexpr int kMaxCalibrationRadius = 64;

// The factor (3 channels, finite, in [0, maxFactor]) for the colour variances of `input`; an
// empty image when the input has no halves or radius is 0 (nothing to calibrate against: keep
// the variances). Pixels whose means or variance are not finite count as missing in both boxes;
// a box without any sample variance gets the factor min(1, maxFactor). maxFactor 1 lets the
// calibration only lower the variance (stratification can only lower the variance of a mean;
// a box whose halves differ by more than the recorded variance says is then taken as noise).
Image colorVarianceCalibration(const DenoiseInput& input, int radius,
                               float maxFactor = std::numeric_limits<float>::infinity());

// variance × factor per element (variance itself when factor is empty). Same shape required.
Image calibratedVariance(const Image& variance, const Image& factor);

// input.whole's colour variance of the mean calibrated (the two calls above), or an empty image
// where there is nothing to calibrate against (no halves, radius 0).
Image calibratedWholeColorVariance(const DenoiseInput& input, int radius,
                                   float maxFactor = std::numeric_limits<float>::infinity());

}  // namespace chorus
