#pragma once
// Helpers for testing base denoisers (any BaseDenoiser): running with a fixed thread count,
// finiteness, a feature-blind blur to compare edge preservation against, and the checks every
// denoiser's unit test makes on the synthetic scene. The checks take the per-denoiser bounds as
// parameters (each test file keeps and documents its own) and name the denoiser in failures.
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <limits>
#include <memory>
#include <string>

#include "common/image/image.h"
#include "denoise/base/base_denoiser.h"
#include "tests/support/synthetic_scene.h"

namespace chorus::test {

inline constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
inline constexpr float kInf = std::numeric_limits<float>::infinity();

// Runs the denoiser with at most `threads` TBB threads.
Image runWithThreads(const BaseDenoiser& denoiser, const DenoiseInput& input, int threads);

// "" when every value is finite, else a description of the first non-finite value.
std::string firstNonFinite(const Image& image);

// True when both images have the same shape and bit-identical values.
bool bitIdentical(const Image& a, const Image& b);

// Gaussian blur of standard deviation sigma (window radius ⌈3σ⌉, clipped and renormalised at
// the borders), blind to features: what a denoiser that ignores edges would produce.
Image gaussianBlur(const Image& image, float sigma);

// Largest |value − expected[c]| over all pixels, per channel c of an RGB image.
float maxDeviationFrom(const Image& image, const float expected[3]);

// The size × size (or width × height) synthetic scene, other options from `extra`.
SyntheticScene syntheticScene(int size, SyntheticSceneOptions extra = {});
SyntheticScene syntheticScene(int width, int height, SyntheticSceneOptions extra = {});

// ---- Checks on the 64×64 synthetic scene (syntheticScene(64)) ----------------------------

// A denoiser as a function of its input, for checks that vary how it runs (parameters, halves).
using DenoiseFn = std::function<Image(DenoiseInput)>;

// The output is finite and its relMSE times minImprovement stays below the noisy input's.
void expectReducesRelMse(const BaseDenoiser& denoiser, double minImprovement);

// Near feature edges (edgeMask), the output's relMSE times vsNoisy stays below the noisy
// input's and, when vsBlur > 0, times vsBlur below that of gaussianBlur(input, blurSigma).
void expectKeepsFeatureEdgesSharp(const BaseDenoiser& denoiser, double vsNoisy, float blurSigma = 0,
                                  double vsBlur = 0);

// With a noise-free constant colour (0.3, 1.5, 7) every output value stays within
// relTolerance × 7 of it.
void expectConstantStaysConstant(const std::string& name, const DenoiseFn& run, float relTolerance);
void expectConstantStaysConstant(const BaseDenoiser& denoiser, float relTolerance);

// With a black image the output is exactly black.
void expectBlackStaysBlack(const std::string& name, const DenoiseFn& run);
void expectBlackStaysBlack(const BaseDenoiser& denoiser);

// On half A, half B and the full buffer (with their halves, or without when !withHalves) the
// output is 64 wide, RGB, finite, and its relMSE times minImprovement stays below the input's.
void expectRunsOnEveryBufferPart(const BaseDenoiser& denoiser, bool withHalves,
                                 double minImprovement);

// With one and with four samples per quarter (K = 4; one sample: 4 spp in total, so a half's
// quarters have no variance of their own), on half A, half B and the full buffer with halves, the
// output is finite and its relMSE times the bound for that sample count stays below the input's.
void expectReducesRelMseOnEveryBufferPart(const BaseDenoiser& denoiser,
                                          double minImprovementOneSample,
                                          double minImprovementFourSamples);

// Bit-identical outputs with one and with two threads on `scene`'s full buffer.
void expectDeterministicAcrossThreads(const BaseDenoiser& denoiser, const SyntheticScene& scene);

// The output is finite for `scene`'s full buffer after `corrupt` has written NaN, Inf or other
// bad values into it.
void expectFiniteOnNonFiniteInputs(const BaseDenoiser& denoiser, const SyntheticScene& scene,
                                   const std::function<void(DenoiseInput&)>& corrupt);

// createDenoiser(spec) gives a denoiser called `name` with these requirements (returned for
// more checks).
std::unique_ptr<BaseDenoiser> expectCreates(const std::string& spec, const std::string& name,
                                            DenoiserRequirements requirements);

// createDenoiser refuses every one of these specs.
void expectRejected(std::initializer_list<const char*> specs);

// createDenoiser(spec) returns the noisy input bit for bit.
void expectIdentity(const std::string& spec);

// The denoiser refuses a full buffer without halves.
void expectNeedsHalves(const BaseDenoiser& denoiser);

// On the spp4 buffers of the Tungsten peers room and glossy (below `shared`), the output is
// finite and halves relMSE against the reference; `report` may print more per scene.
void expectHalvesTungstenPeerRelMse(
    const BaseDenoiser& denoiser, const std::filesystem::path& shared,
    const std::function<void(const std::string& scene, const DenoiseInput&,
                             const Image& reference)>& report = {});

}  // namespace chorus::test
