#pragma once
// Discrete and piecewise-constant distributions for light sampling.
#include <span>
#include <vector>

#include "renderer/math/vec.h"

namespace chorus::render {

// Walker/Vose alias table: O(1) sampling of index i with probability weights[i] / Σ weights.
class AliasTable {
 public:
  AliasTable() = default;
  explicit AliasTable(std::span<const float> weights);  // weights ≥ 0, not all 0

  // Returns an index; *pmf receives its probability, *uRemapped (optional) a fresh uniform
  // number in [0,1) recovered from u for reuse.
  int sample(float u, float* pmf, float* uRemapped = nullptr) const;
  float pmf(int index) const;
  int size() const { return int(probability_.size()); }

 private:
  std::vector<float> probability_, pmf_;
  std::vector<int> alias_;
};

// Piecewise-constant 2D distribution over [0,1]² on an nu × nv grid (row-major f[v * nu + u]),
// sampled by the marginal in v then the conditional in u. Used for environment maps, where f is
// luminance × sin θ.
class PiecewiseConstant2D {
 public:
  PiecewiseConstant2D() = default;
  PiecewiseConstant2D(std::span<const float> f, int nu, int nv);

  // A point in [0,1)² and its density with respect to area on [0,1]².
  Vec2f sample(Vec2f u, float* pdf) const;
  float pdf(Vec2f p) const;

 private:
  int nu_ = 0, nv_ = 0;
  std::vector<float> conditionalCdf_;  // nv rows of nu + 1
  std::vector<float> conditionalFunc_, rowIntegral_, marginalCdf_;
  float integral_ = 0;
  // Guide tables of the cdfs (see distributions.cpp): nv rows of guideSize(nu) + 1 entries, and
  // guideSize(nv) + 1.
  std::vector<int> conditionalGuide_, marginalGuide_;
};

}  // namespace chorus::render
