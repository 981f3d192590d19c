#pragma once
// Synthetic renders with a known truth, and simple "base denoisers" whose errors differ in
// space, for validating and tuning the ensemble without a renderer (tests/ensemble_*_test.cpp,
// tools/bench/bench_ensemble_options.cpp). Not used by the renderer or the CLI.
//
// Scenes (radiance = albedo × shading, noise-free albedo and normal features):
//   regions  piecewise-constant albedo cells with different normals under smooth lighting
//   shadows  smooth albedo, lighting with hard shadow edges and a fine stripe pattern that
//            the features do not show
//   hdr      a few very bright emitters and highlights (values up to ~50) on a dim room
// Samples: per pixel, per sub-buffer, `sppPerSplit` samples of μ + σ(μ)·g with
// σ(μ) = noise·√(μ + 0.05) and g standard normal; with `fireflyRate` > 0 a sample is replaced
// by μ + 30·noise·(1 + μ)·u (u uniform) with that probability (heavy tail, still unbiased up
// to that known mean shift, which is part of the truth).
//
// Base denoisers (names for createSyntheticDenoiser):
//   box1    3×3 box filter                 — low bias, high variance
//   gauss3  Gaussian σ = 3 (radius 9)       — low variance, blurs every edge
//   guided  joint bilateral on albedo/normal, σ_s = 4 — sharp on feature edges, blurs
//           lighting detail the features do not show
//   nlm     pixel bilateral with a variance-normalised colour distance (Rousselle-style),
//           σ_s = 3 — keeps strong lighting edges, leaves noise on weak ones
//   biased  Gaussian σ = 1.5 of min(colour, 1.5) — clamps highlights (an LDR-trained
//           denoiser's typical bias)
//   median5 per channel the median of the 5×5 window — nonlinear: its error has no linear
//           relation to its input's
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "denoise/base/base_denoiser.h"
#include "denoise/buffers/sample_buffers.h"
#include "denoise/pipeline/ensemble_sources.h"

namespace chorus::synthetic {

enum class SceneKind { Regions, Shadows, Hdr };
std::string_view sceneName(SceneKind kind);

struct Scene {
  Image truth;   // expected value of a sample (RGB)
  Image albedo;  // RGB
  Image normal;  // unit XYZ
};
Scene makeScene(SceneKind kind, int width, int height);

struct NoiseModel {
  float noise = 1.0f;        // per-sample σ = noise·√(μ + 0.05)
  int sppPerSplit = 4;       // samples per pixel in each sub-buffer
  float fireflyRate = 0.0f;  // probability that a sample is a firefly
};
// The expected value of a sample under `model` (the truth shifted by the firefly mean).
Image expectedValue(const Scene& scene, const NoiseModel& model);
// `splits` independent sub-buffers of the scene (features noise-free).
SampleBuffers renderBuffers(const Scene& scene, const NoiseModel& model, int splits, uint64_t seed);

// "box1", "gauss3", "guided", "nlm", "biased", "median5"; throws chorus::Error otherwise.
std::unique_ptr<BaseDenoiser> createSyntheticDenoiser(const std::string& name);
// A denoiser that returns a fixed image whatever its input (e.g. the truth: a perfect member).
std::unique_ptr<BaseDenoiser> createConstantDenoiser(const std::string& name, const Image& image);

// One documented validation case.
struct Case {
  std::string name;
  SceneKind scene;
  NoiseModel noise;
  std::vector<std::string> members;
  uint64_t seed;
};
// The documented set of cases (3 scenes × 3 noise levels × 3 member sets = 27), see README.
std::vector<Case> standardCases();

// A case rendered (K = 4) and denoised by its members on A, B and full.
struct PreparedCase {
  Image truth;  // expected value (what errors are measured against)
  EnsembleGuides guides;
  std::vector<BaseOutputs> bases;
};
PreparedCase prepareCase(const Case& c, int width, int height);

}  // namespace chorus::synthetic
