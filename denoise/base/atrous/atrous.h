#pragma once
// Edge-avoiding à-trous wavelet filter (Dammertz, Sewtz, Hanika, Lensch, HPG 2010) with the
// edge-stopping weights of SVGF (Schied et al., HPG 2017, §4.3), without SVGF's temporal part;
// values as in ../shared/docs/base-denoisers.md §6. The fast member, for previews.
//
// Iteration i = 0 … N−1 filters the previous result with the 5×5 B3-spline kernel
// h = (1/16, 1/4, 3/8, 1/4, 1/16)² with taps 2^i pixels apart, weighted per tap q of pixel p by
//   w_z = exp(−|z(p) − z(q)| / (σ_z |∇z(p)·(p − q)| + ε_z))
//   w_n = max(0, n(p)·n(q))^σ_n
//   w_l = exp(−|l(p) − l(q)| / (σ_l √(g3×3 ∗ Var_l)(p) + ε_l))
// and propagates the luminance variance: Var'(p) = Σ h² w² Var(q) / (Σ h w)².
// Our choices where the papers leave them open:
//   - depth is divided by the largest finite depth; ∇z per axis is the one-sided difference of
//     smaller magnitude (a central difference would open every depth edge); ε_z = 1e-3;
//   - normals are normalised; a pixel without a normal (zero vector) does not constrain w_n;
//   - luminance a = (0.2126, 0.7152, 0.0722); Var_l = (Σ_c a_c √V_c)² from the per-channel
//     variances of the mean (channels are positively correlated; Σ a_c² V_c under-estimates);
//   - optional albedo demodulation: colour and its variance divided by max(albedo, 1e-3) (and
//     its square) before filtering, the result multiplied back after — except within one pixel
//     of a pixel whose albedo is below 0.02 in every channel (a light seen directly records a
//     black albedo in chorus's buffers; demodulated, its mixed edge pixels would leak);
//   - optional firefly clamp (preview only, biased): luminance limited to 10× its 3×3 median;
//   - from `symmetricFrom` samples per pixel on, w_l takes the larger of p's and q's inverse
//     tolerances: SVGF's rule asks only p, so a noisy highlight (its blurred variance large)
//     averages in the well-measured pixels around it, a bias that stays at any sample count
//     (flight-helmet-studio 256 spp: 5.4× the noisy input). Below it the variances come from
//     too few samples: a pixel whose few samples agree would veto every neighbour (Cornell
//     box 4 spp: 0.024 → 0.062 relMSE with the rule on);
//   - optionally (`borrow` < 1, below `symmetricFrom`; the previews' members), the variance in
//     w_l is max(borrow · B, min(Var_l(p), B)) with B = g3×3 ∗ Var_l: lowered towards the
//     pixel's own variance where that is smaller, by at most 1 / borrow. SVGF's blur gives a
//     pixel whose few samples are all dark (a shadow line, the rim of a lit patch) its bright
//     neighbours' variance, and with it a tolerance wide enough to take their light
//     (interior-doorway 16 spp: relMSE 0.48, noisy 0.42; with borrow 0.5: 0.16). Off by default:
//     better alone and in the preview, but the default ensemble blends worse with it at 4–8 spp
//     (docs/members/sbf-atrous-bilateral.md);
//   - optionally (`calibrate` R > 0, with halves in the input), V_c is the recorded variance of
//     the mean brought to the halves' level over a box of radius R (variance_calibration.h): the
//     sampler stratifies, so the recorded one overestimates the noise, most where the image is
//     smooth within a pixel, and the tolerances with it. Off by default: better alone (R 3),
//     but the default ensemble blends 0.3 % worse with it (docs/variance-calibration.md);
//   - the 3×3 blur of Var_l takes a bright pixel's variance in relative units (divided by
//     (l / knee)² where l exceeds `varianceKnee` × the level's mean |luminance|, multiplied back
//     by p's own): blurred as is, a highlight's variance gave the dark pixels beside it a
//     tolerance wide enough to take its light (selection_knee.h; docs/members/).
#include <string>

#include "denoise/base/base_denoiser.h"
#include "denoise/base/param_map.h"

namespace chorus {

struct AtrousParams {
  static constexpr int kMaxIterations = 6;  // the zero margins grow as 2^iterations
  static constexpr int kIterationsFromSamples = -1;
  // N: à-trous levels, tap spacing 2^i (5 → a 125-pixel footprint); kIterationsFromSamples
  // (default, also `iterations=-1`): iterationsForSamples of the render's samples per pixel.
  int iterations = kIterationsFromSamples;
  float sigmaZ = 1.0f;          // σ_z: depth tolerance in units of the depth gradient (SVGF)
  float sigmaN = 128.0f;        // σ_n: exponent of the normal weight (SVGF)
  float sigmaL = 4.0f;          // σ_l: luminance tolerance in noise standard deviations (SVGF)
  bool demodulate = true;       // filter colour / albedo (measured: docs/members/)
  bool clampFireflies = false;  // clamp luminance to 10× the 3×3 median first (docs/members/)
  // From this many samples per pixel of the render on, a tap's own tolerance counts too:
  // w_l uses the larger of p's and q's inverse tolerances (the stricter), docs/members/.
  float symmetricFrom = 32.0f;
  // Below symmetricFrom, the least share of the 3×3-blurred variance a pixel's tolerance keeps
  // where its own variance is smaller (1: SVGF's blurred variance alone, at any sample count).
  float borrow = 1.0f;
  // The knee above which the variance blur is relative (0: SVGF's blur everywhere).
  float varianceKnee = 8.0f;
  // The box radius of the colour variance's calibration to the input's halves (0, default: the
  // recorded variance as is; inputs without halves keep it too).
  int calibrationRadius = 0;

  // Reads overrides: iterations, sigmaZ, sigmaN, sigmaL, demodulate, clampFireflies,
  // symmetricFrom, borrow, varianceKnee, calibrate (the calibration radius).
  // Throws chorus::Error for a value out of range.
  static AtrousParams fromParams(ParamMap& params);
};

// The levels for a render of `spp` samples per pixel: round(9 − log2 spp) within [2, 5], i.e.
// 5 up to 22 spp, 4 at 32, 3 at 64, 2 from 91 on (5 without a sample count). The edge-stopping
// tolerances follow the noise, but every level still averages what lies within them, and the
// detail below the tolerance that a wide footprint averages away is the error once the noise
// is small. Chosen on the corpus's tuning half (docs/members/sbf-atrous-bilateral.md).
int iterationsForSamples(double spp);

// Which implementation of the inner kernel runs: the widest the CPU supports (AVX-512F, AVX2
// or SSE2), or a narrower one. All give bit-identical results; tests compare them.
enum class AtrousKernelPath { Widest, Avx2, Sse2, Scalar };

// Runs the filter on one buffer (colour and its variance, albedo, normal, depth) that holds
// `sampleShare` of the render's samples (DenoiseInput::sampleShare); with `colorVariance`, that
// variance of the colour's mean instead of the buffer's.
Image runAtrous(const SubBuffer& buffer, const AtrousParams& params,
                AtrousKernelPath path = AtrousKernelPath::Widest, double sampleShare = 1.0,
                const Image* colorVariance = nullptr);

class Atrous : public BaseDenoiser {
 public:
  explicit Atrous(AtrousParams params = {}) : params_(params) {}
  std::string name() const override { return "atrous"; }
  // The calibration (calibrate=R) compares the halves when the input has them.
  DenoiserRequirements requirements() const override {
    return {.features = true, .halves = false, .readsHalves = params_.calibrationRadius > 0};
  }
  Image run(const DenoiseInput& input) const override;

 private:
  AtrousParams params_;
};

}  // namespace chorus
