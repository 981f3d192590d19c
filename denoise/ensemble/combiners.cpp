#include "denoise/ensemble/combiners.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>

#include "common/error.h"
#include "common/stopwatch.h"
#include "denoise/ensemble/blend.h"
#include "denoise/ensemble/pairwise_solver.h"

namespace chorus {
namespace {

constexpr Combiner kAllCombiners[] = {Combiner::Ensemble,  Combiner::Average,
                                      Combiner::OnehotPre, Combiner::OnehotPost,
                                      Combiner::Oracle,    Combiner::OracleUnconstrained};

class StageClock {
 public:
  explicit StageClock(std::vector<StageTime>& times) : times_(times) {}
  void stop(const std::string& stage) { times_.push_back({stage, clock_.restart()}); }

 private:
  std::vector<StageTime>& times_;
  Stopwatch clock_;
};

std::vector<Image> zeroMaps(int n, int width, int height, int channels) {
  return std::vector<Image>(size_t(n), Image(width, height, channels));
}

struct SolvedWeights {
  std::vector<Image> weights;
  std::vector<BaseMask> valid;
  std::vector<char> noisyFallback;  // MseRows::noisyFallback per pixel
};

// Rows per task of the solve: ⟨M⟩ is computed band by band (bounded memory, the window's halo
// rows recomputed per band: 64 rows keep that to 1.16x for radius 5, and the step 6 % faster
// than 32 rows did); results do not depend on the band height.
constexpr int kBandRows = 64;

// Per-pixel weights from ⟨M⟩ (or the oracle's true matrix).
SolvedWeights solveWeights(const MseEstimator& estimator, SolverKind solver,
                           const SimplexQpOptions& qp, uint64_t seed) {
  const int n = estimator.baseCount(), groups = estimator.groups();
  const int w = estimator.width(), h = estimator.height();
  SolvedWeights solved{zeroMaps(n, w, h, groups), std::vector<BaseMask>(size_t(w) * size_t(h)),
                       std::vector<char>(size_t(w) * size_t(h))};
  const int bands = (h + kBandRows - 1) / kBandRows;
  tbb::parallel_for(0, bands, [&](int band) {
    const MseRows rows = estimator.rows(band * kBandRows, (band + 1) * kBandRows);
    PixelMse pixel;
    for (int y = rows.y0(); y < rows.y1(); ++y) {
      // The active set starts from the left neighbour's support (neighbouring optima usually
      // share it; the solver keeps the result independent of the start), from scratch at the
      // start of each row.
      std::array<BaseMask, 3> support;
      support.fill(~BaseMask(0));
      for (int x = 0; x < w; ++x) {
        rows.pixel(x, y, pixel);
        const size_t p = size_t(y) * size_t(w) + size_t(x);
        solved.valid[p] = pixel.valid;
        solved.noisyFallback[p] = rows.noisyFallback(x, y);
        for (int g = 0; g < groups; ++g) {
          WeightVector weights;
          if (solver == SolverKind::ActiveSet) {
            SimplexQpResult result =
                solveSimplexQp(pixel.h[size_t(g)], pixel.valid, qp, support[size_t(g)]);
            weights = result.weights;
            support[size_t(g)] = result.support;
          } else {
            weights =
                solvePairwise(pixel.h[size_t(g)], seed, p * size_t(groups) + size_t(g), pixel.valid)
                    .weights;
          }
          for (int i = 0; i < n; ++i) solved.weights[size_t(i)](x, y, g) = float(weights[i]);
        }
      }
    }
  });
  return solved;
}

// Per-base estimated MSE maps (the diagonal of H; the common constant does not change which
// base is least), divided by their mean so that float storage works for any magnitude.
// Invalid bases get 1e30 so they are not chosen (finite, so that filtering them is safe).
struct DiagonalMaps {
  std::vector<Image> maps;
  std::vector<BaseMask> valid;
};
DiagonalMaps diagonalMaps(const MseEstimator& estimator) {
  const int n = estimator.baseCount(), groups = estimator.groups();
  const int w = estimator.width(), h = estimator.height();
  const size_t pixels = size_t(w) * size_t(h);
  std::vector<double> values(pixels * size_t(groups) * size_t(n));
  DiagonalMaps out{zeroMaps(n, w, h, groups), std::vector<BaseMask>(pixels)};
  const int bands = (h + kBandRows - 1) / kBandRows;
  tbb::parallel_for(0, bands, [&](int band) {
    const MseRows rows = estimator.rows(band * kBandRows, (band + 1) * kBandRows);
    for (int y = rows.y0(); y < rows.y1(); ++y)
      for (int x = 0; x < w; ++x) {
        const size_t p = size_t(y) * size_t(w) + size_t(x);
        out.valid[p] = rows.valid(x, y);
        for (int g = 0; g < groups; ++g)
          for (int i = 0; i < n; ++i)
            values[(p * size_t(groups) + size_t(g)) * size_t(n) + size_t(i)] =
                rows.diagonal(x, y, g, i);
      }
  });
  double sum = 0;
  size_t count = 0;
  for (double v : values)
    if (std::isfinite(v)) sum += std::abs(v), ++count;
  double scale = count > 0 ? sum / double(count) : 1.0;
  if (!(scale > 0.0) || !std::isfinite(scale)) scale = 1.0;
  for (size_t p = 0; p < pixels; ++p)
    for (int g = 0; g < groups; ++g)
      for (int i = 0; i < n; ++i) {
        const double v = values[(p * size_t(groups) + size_t(g)) * size_t(n) + size_t(i)] / scale;
        const bool usable = ((out.valid[p] >> i) & 1u) && std::isfinite(v);
        out.maps[size_t(i)].data()[p * size_t(groups) + size_t(g)] =
            usable ? float(std::min(v, 1e30)) : 1e30f;
      }
  return out;
}

// One-hot weights: per pixel and group, 1 for the valid base with the least value.
std::vector<Image> argminOneHot(const std::vector<Image>& maps,
                                const std::vector<BaseMask>& valid) {
  const int n = int(maps.size()), groups = maps[0].channels();
  std::vector<Image> out = zeroMaps(n, maps[0].width(), maps[0].height(), groups);
  for (size_t p = 0; p < valid.size(); ++p)
    for (int g = 0; g < groups; ++g) {
      const size_t e = p * size_t(groups) + size_t(g);
      int best = -1;
      for (int i = 0; i < n; ++i) {
        if (!((valid[p] >> i) & 1u)) continue;
        if (best < 0 || maps[size_t(i)].data()[e] < maps[size_t(best)].data()[e]) best = i;
      }
      if (best < 0)
        for (int i = 0; i < n; ++i) out[size_t(i)].data()[e] = 1.0f / float(n);
      else
        out[size_t(best)].data()[e] = 1.0f;
    }
  return out;
}

// One run of every base: outputsOf(bases, &BaseOutputs::a) are the y_i^A.
std::vector<const Image*> outputsOf(std::span<const BaseOutputs* const> bases,
                                    Image BaseOutputs::*run) {
  std::vector<const Image*> images;
  for (const BaseOutputs* base : bases) images.push_back(&(base->*run));
  return images;
}

// The noisy counterpart of every run the weights are applied to: the value of its blend where
// no base is finite, and what the noisy fallback puts there. For the runs without quarter k
// (bases without half runs) the mean of the other quarters that hold samples (below 4 spp some
// hold none, and their zeros would darken it).
struct NoisyRuns {
  const Image& full;
  const Image& a;
  const Image& b;
  std::vector<Image> heldOut;
};
NoisyRuns noisyRunsOf(const EnsembleGuides& guides, bool halfRuns) {
  NoisyRuns noisy{guides.color, guides.colorA, guides.colorB, {}};
  const std::array<bool, 4> sampled = sampledQuarters(guides.quarters);
  for (size_t k = 0; k < 4 && !halfRuns; ++k) {
    Image& without = noisy.heldOut.emplace_back(guides.width(), guides.height(), 3);
    std::vector<const float*> others;
    for (size_t j = 0; j < 4; ++j)
      if (j != k && sampled[j]) others.push_back(guides.quarters[j].data());
    if (others.empty()) continue;  // no samples without quarter k: 0, as the image starts
    for (size_t e = 0; e < without.size(); ++e) {
      float sum = 0;
      for (const float* q : others) sum += q[e];
      without.data()[e] = sum / float(others.size());
    }
  }
  return noisy;
}

// The weights applied to every run: full buffer, and the half runs (a, b) or, where the bases
// have none, the held-out runs.
struct Blends {
  Image full, a, b;
  std::vector<Image> heldOut;

  ColorGuide colorGuide(const WeightFilterOptions& options) const {
    return heldOut.empty() ? makeColorGuide(full, a, b, options)
                           : makeColorGuide(full, heldOut, options);
  }
};
Blends blendAll(const std::vector<Image>& weights, std::span<const BaseOutputs* const> bases,
                const NoisyRuns& noisy) {
  Blends blends{blend(weights, outputsOf(bases, &BaseOutputs::full), noisy.full), {}, {}, {}};
  if (bases[0]->hasHalfRuns()) {
    blends.a = blend(weights, outputsOf(bases, &BaseOutputs::a), noisy.a);
    blends.b = blend(weights, outputsOf(bases, &BaseOutputs::b), noisy.b);
    return blends;
  }
  for (size_t k = 0; k < 4; ++k) {
    std::vector<const Image*> runs;
    for (const BaseOutputs* base : bases) runs.push_back(&base->heldOut[k]);
    blends.heldOut.push_back(blend(weights, runs, noisy.heldOut[k]));
  }
  return blends;
}

// Weight filter step shared by the combiners: guided by the blend of `weights`.
std::vector<Image> filterWeights(const std::vector<Image>& weights,
                                 const std::vector<BaseMask>& valid,
                                 std::span<const BaseOutputs* const> bases, const NoisyRuns& noisy,
                                 const EnsembleGuides& guides, const WeightFilterOptions& options,
                                 bool nonNegative) {
  const ColorGuide guide = blendAll(weights, bases, noisy).colorGuide(options);
  const std::vector<Image> filtered =
      crossBilateralFilter(weights, guide, guides.normal, guides.albedo, options);
  return renormalizeWeights(filtered, valid, weights, nonNegative);
}

}  // namespace

std::string_view combinerName(Combiner combiner) {
  switch (combiner) {
    case Combiner::Ensemble:
      return "ensemble";
    case Combiner::Average:
      return "average";
    case Combiner::OnehotPre:
      return "onehot-pre";
    case Combiner::OnehotPost:
      return "onehot-post";
    case Combiner::Oracle:
      return "oracle";
    case Combiner::OracleUnconstrained:
      return "oracle-unconstrained";
  }
  return "?";
}

Combiner parseCombiner(const std::string& name) {
  std::string known;
  for (Combiner c : kAllCombiners) {
    if (combinerName(c) == name) return c;
    known += (known.empty() ? "" : ", ") + std::string(combinerName(c));
  }
  throw Error("unknown combiner '" + name + "' (known: " + known + ")");
}

bool needsReference(Combiner combiner) {
  return combiner == Combiner::Oracle || combiner == Combiner::OracleUnconstrained;
}

std::string_view solverName(SolverKind solver) {
  return solver == SolverKind::ActiveSet ? "active-set" : "pairwise";
}

SolverKind parseSolver(const std::string& name) {
  if (name == "active-set") return SolverKind::ActiveSet;
  if (name == "pairwise") return SolverKind::Pairwise;
  throw Error("unknown solver '" + name + "' (known: active-set, pairwise)");
}

CombineResult combine(const EnsembleGuides& guides, std::span<const BaseOutputs* const> bases,
                      const CombineOptions& options, const Image* reference) {
  checkEnsembleInputs(guides, bases);
  if (needsReference(options.combiner) && !reference)
    throw Error("the " + std::string(combinerName(options.combiner)) +
                " combiner needs a reference image");
  const int n = int(bases.size()), w = guides.width(), h = guides.height();
  const NoisyRuns noisy = noisyRunsOf(guides, bases[0]->hasHalfRuns());
  CombineResult result;
  StageClock clock(result.times);

  std::vector<BaseMask> valid;
  std::vector<char> fallback;  // ensemble only: the noisy value replaces the blend there
  std::optional<MseEstimator> ensembleEstimator;
  bool nonNegative = true, filter = options.filter.enabled;
  // onehot-pre filters the MSE maps, not the weights, and times its own stages.
  const bool filtersBeforeChoosing = options.combiner == Combiner::OnehotPre;
  switch (options.combiner) {
    case Combiner::Ensemble: {
      const MseEstimator& estimator = ensembleEstimator.emplace(guides, bases, options.mse);
      SolvedWeights solved = solveWeights(estimator, options.solver, options.qp, options.seed);
      result.rawWeights = std::move(solved.weights);
      valid = std::move(solved.valid);
      fallback = std::move(solved.noisyFallback);
      break;
    }
    case Combiner::Oracle:
    case Combiner::OracleUnconstrained: {
      // Per pixel and relative: with the truth there is no noise to average over a window, and
      // dividing each channel by (r² + ε) makes the per-pixel objective exactly the pixel's
      // relMSE, so the oracle is the best per-pixel blend for the metric the sweeps report.
      MseOptions oracleMse = options.mse;
      oracleMse.windowRadius = 0;
      oracleMse.relative = true;
      const MseEstimator estimator = MseEstimator::oracle(guides, bases, *reference, oracleMse);
      SimplexQpOptions qp = options.qp;
      nonNegative = qp.nonNegative = options.combiner == Combiner::Oracle;
      SolvedWeights solved = solveWeights(estimator, SolverKind::ActiveSet, qp, options.seed);
      result.rawWeights = std::move(solved.weights);
      valid = std::move(solved.valid);
      filter = false;
      break;
    }
    case Combiner::Average: {
      const MseEstimator estimator(guides, bases, options.mse);
      result.rawWeights = zeroMaps(n, w, h, estimator.groups());
      valid.resize(size_t(w) * size_t(h));
      for (size_t p = 0; p < valid.size(); ++p) {
        valid[p] = estimator.validAt(p);
        const int count = std::popcount(valid[p]);
        for (int i = 0; i < n; ++i)
          for (int g = 0; g < estimator.groups(); ++g)
            result.rawWeights[size_t(i)].data()[p * size_t(estimator.groups()) + size_t(g)] =
                count == 0               ? 1.0f / float(n)
                : ((valid[p] >> i) & 1u) ? 1.0f / float(count)
                                         : 0.0f;
      }
      filter = false;
      break;
    }
    case Combiner::OnehotPre: {
      const MseEstimator estimator(guides, bases, options.mse);
      DiagonalMaps diagonal = diagonalMaps(estimator);
      valid = std::move(diagonal.valid);
      clock.stop("solve");
      if (filter) {
        // Guided by the average blend: the combiner has no weights before this step.
        std::vector<Image> uniform = zeroMaps(n, w, h, 1);
        for (Image& map : uniform) map.fill(1.0f / float(n));
        diagonal.maps = crossBilateralFilter(
            diagonal.maps, blendAll(uniform, bases, noisy).colorGuide(options.filter),
            guides.normal, guides.albedo, options.filter);
      }
      result.rawWeights = argminOneHot(diagonal.maps, valid);
      clock.stop("filter");
      filter = false;
      break;
    }
    case Combiner::OnehotPost: {
      const MseEstimator estimator(guides, bases, options.mse);
      DiagonalMaps diagonal = diagonalMaps(estimator);
      valid = std::move(diagonal.valid);
      result.rawWeights = argminOneHot(diagonal.maps, valid);
      break;
    }
  }
  if (!filtersBeforeChoosing) clock.stop("solve");

  if (filter) {
    result.weights =
        filterWeights(result.rawWeights, valid, bases, noisy, guides, options.filter, nonNegative);
    clock.stop("filter");
  } else {
    result.weights = result.rawWeights;
    if (!filtersBeforeChoosing) clock.stop("filter");
  }

  if (ensembleEstimator && options.mse.memberFallback > 0) {
    // The blend where it is plausible, else one member: its weights become one-hot there.
    const std::vector<int> member = ensembleEstimator->memberFallbacks(result.weights);
    const int channels = result.weights[0].channels();
    for (size_t p = 0; p < member.size(); ++p) {
      if (member[p] < 0) continue;
      ++result.memberFallbackPixels;
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < channels; ++c)
          result.weights[size_t(i)].data()[p * size_t(channels) + size_t(c)] =
              i == member[p] ? 1.0f : 0.0f;
    }
  }
  Blends blends = blendAll(result.weights, bases, noisy);
  if (!fallback.empty()) {
    result.noisyFallback = Image(w, h, 1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (!fallback[size_t(y) * size_t(w) + size_t(x)] || !std::isfinite(guides.color(x, y, 0)) ||
            !std::isfinite(guides.color(x, y, 1)) || !std::isfinite(guides.color(x, y, 2)))
          continue;
        result.noisyFallback(x, y, 0) = 1.0f;
        ++result.noisyFallbackPixels;
        for (int c = 0; c < 3; ++c) {
          blends.full(x, y, c) = noisy.full(x, y, c);
          if (!blends.a.empty()) {
            blends.a(x, y, c) = noisy.a(x, y, c);
            blends.b(x, y, c) = noisy.b(x, y, c);
          }
          for (size_t k = 0; k < blends.heldOut.size(); ++k)
            blends.heldOut[k](x, y, c) = noisy.heldOut[k](x, y, c);
        }
      }
  }
  result.image = std::move(blends.full);
  result.mseEstimate = blends.heldOut.empty()
                           ? estimatedBlendMse(blends.a, blends.b, guides.colorA, guides.colorB)
                           : heldOutBlendMse(blends.heldOut, guides.quarters);
  result.imageA = std::move(blends.a);
  result.imageB = std::move(blends.b);
  clock.stop("blend");
  return result;
}

}  // namespace chorus
