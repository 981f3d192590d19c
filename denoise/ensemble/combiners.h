#pragma once
// Combining base-denoiser outputs into one image: the ensemble (Zheng et al. 2021) and the
// baselines it is compared with. A pure function of its inputs (no I/O, deterministic for any
// thread count), so that sweeps can run every base denoiser once and combine any subset of
// the same BaseOutputs with any combiner.
//
//   ensemble              per-pixel weights minimising the estimated MSE ⟨M⟩ on the simplex
//                         (solver: exact active set, or the paper's pairwise iteration), then
//                         the joint-bilateral weight filter, then the blend
//   average               uniform weights over the bases that are finite at the pixel
//   onehot-pre            per pixel the base with the least estimated MSE, the per-base MSE
//                         maps being smoothed with the weight filter first (guided by the
//                         average blend)
//   onehot-post           the base with the least raw estimated MSE, then the one-hot maps are
//                         smoothed with the weight filter and renormalised
//   oracle                like the ensemble but with the true error matrix (needs a reference):
//                         per-pixel weights on the simplex minimising the pixel's relMSE (no
//                         window, each channel divided by r² + ε), not filtered
//   oracle-unconstrained  the same with only Σw = 1 (weights may be negative)
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "denoise/ensemble/ensemble_inputs.h"
#include "denoise/ensemble/mse_estimate.h"
#include "denoise/ensemble/simplex_qp.h"
#include "denoise/ensemble/weight_filter.h"

namespace chorus {

enum class Combiner { Ensemble, Average, OnehotPre, OnehotPost, Oracle, OracleUnconstrained };
std::string_view combinerName(Combiner combiner);
Combiner parseCombiner(const std::string& name);  // throws chorus::Error listing the names
bool needsReference(Combiner combiner);

enum class SolverKind { ActiveSet, Pairwise };
std::string_view solverName(SolverKind solver);  // "active-set", "pairwise"
SolverKind parseSolver(const std::string& name);

struct CombineOptions {
  Combiner combiner = Combiner::Ensemble;
  SolverKind solver = SolverKind::ActiveSet;
  MseOptions mse;
  WeightFilterOptions filter;
  SimplexQpOptions qp;
  uint64_t seed = 1;  // random sequence of the pairwise solver
};

struct StageTime {
  std::string stage;  // e.g. "solve", "filter", "blend", "nfor/A"
  double seconds = 0;
};

struct CombineResult {
  Image image;                    // the blend of the full-buffer outputs (RGB)
  Image imageA, imageB;           // the same weights applied to the half runs (empty without)
  std::vector<Image> weights;     // final weights, one map per base: 3 channels (per-channel
                                  // form) or 1 (summed form)
  std::vector<Image> rawWeights;  // the weights before the weight filter
  Image mseEstimate;              // estimatedBlendMse or heldOutBlendMse of the result (RGB)
  Image noisyFallback;            // 1 where the ensemble's result is the noisy value
                                  // (MseOptions::noisyFallback), else 0 (1 channel)
  size_t noisyFallbackPixels = 0;
  size_t memberFallbackPixels = 0;  // where one member replaced the blend (memberFallback)
  std::vector<StageTime> times;     // "solve", "filter", "blend"
};

// Throws chorus::Error for inconsistent inputs, or an oracle combiner without reference.
CombineResult combine(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases,
                      const CombineOptions& options, const Image* reference = nullptr);

}  // namespace chorus
