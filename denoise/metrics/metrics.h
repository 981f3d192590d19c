#pragma once
// Image error metrics: one implementation for tests, `chorus compare`, denoise and sweep.
// All take an image and a reference of the same shape and average over every pixel and channel
// (pass RGB images: alpha is not special-cased). Accumulation is in double.
//
//   MSE     mean (x − r)²
//   relMSE  mean (x − r)² / (r² + ε), ε = 0.01 (Rousselle et al. 2011; the ensemble paper's form)
//   PSNR    10 log10(1 / MSE) in dB: raw linear values, peak 1 (the displayable range [0, 1]);
//           +inf for identical images
//   SSIM    Wang et al. 2004 on display values t(v) = clamp(v, 0, 1)^(1/2.2), per channel, 11×11
//           Gaussian window with σ = 1.5 (weights normalised), C1 = 0.01², C2 = 0.03², population
//           statistics, averaged over the windows that fit inside the image (no padding) and over
//           channels — scikit-image's structural_similarity(gaussian_weights=True, sigma=1.5,
//           use_sample_covariance=False, data_range=1). Images smaller than 11 pixels in a
//           dimension use one window of that dimension's size.
//   DSSIM   (1 − SSIM) / 2
//   SMAPE   mean |x − r| / (|x| + |r| + ε), ε = 0.01 (Vogels et al. 2018), in [0, 1)
#include <string>

#include "common/image/image.h"

namespace chorus {

inline constexpr double kRelMseEpsilon = 0.01;
inline constexpr double kSmapeEpsilon = 0.01;

double mse(const Image& image, const Image& reference);
double relMse(const Image& image, const Image& reference, double epsilon = kRelMseEpsilon);
double psnr(const Image& image, const Image& reference);
double ssim(const Image& image, const Image& reference);
double dssim(const Image& image, const Image& reference);
double smape(const Image& image, const Image& reference, double epsilon = kSmapeEpsilon);

struct ImageMetrics {
  double mse = 0, relMse = 0, psnr = 0, ssim = 0, dssim = 0, smape = 0;
};
// All metrics at once. Throws chorus::Error when the shapes differ.
ImageMetrics computeMetrics(const Image& image, const Image& reference);

// The per-pixel relMSE map (mean over channels), for false-colour error images.
Image relMseMap(const Image& image, const Image& reference, double epsilon = kRelMseEpsilon);

}  // namespace chorus
