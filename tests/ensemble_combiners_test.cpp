// The combination step end to end on synthetic renders with a known truth: the ensemble beats
// the best single base output on the documented cases, is consistent, survives extreme and
// non-finite inputs, and every combiner does what it says.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

#include "common/error.h"
#include "denoise/ensemble/combiners.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "tests/support/synthetic_cases.h"

namespace chorus {
namespace {

constexpr Combiner kCombiners[] = {Combiner::Ensemble,  Combiner::Average,
                                   Combiner::OnehotPre, Combiner::OnehotPost,
                                   Combiner::Oracle,    Combiner::OracleUnconstrained};

void expectWeightsOnSimplex(const CombineResult& r, bool nonNegative = true) {
  ASSERT_FALSE(r.weights.empty());
  const size_t count = r.weights[0].size();
  for (size_t e = 0; e < count; ++e) {
    double sum = 0, magnitude = 0;
    for (const Image& w : r.weights) {
      const float v = w.data()[e];
      magnitude += std::abs(v);
      ASSERT_TRUE(std::isfinite(v)) << "element " << e;
      if (nonNegative) {
        ASSERT_GE(v, 0.0f) << "element " << e;
      }
      sum += v;
    }
    // Affine weights (the unconstrained oracle) may be large: float rounding scales with them.
    ASSERT_NEAR(sum, 1.0, 1e-5 * std::max(1.0, magnitude)) << "element " << e;
  }
}

void expectFinite(const Image& image) {
  for (float v : image.values()) ASSERT_TRUE(std::isfinite(v));
}

TEST(EnsembleCombiners, BeatsTheBestBaseOnTheDocumentedSyntheticCases) {
  const std::vector<synthetic::Case> cases = synthetic::standardCases();
  int wins = 0;
  for (const synthetic::Case& c : cases) {
    const synthetic::PreparedCase prepared = synthetic::prepareCase(c, 64, 64);
    double best = std::numeric_limits<double>::infinity();
    for (const BaseOutputs& base : prepared.bases)
      best = std::min(best, relMse(base.full, prepared.truth));
    const CombineResult result = combine(prepared.guides, pointersTo(prepared.bases), {});
    expectWeightsOnSimplex(result);
    const double ensemble = relMse(result.image, prepared.truth);
    wins += ensemble < best;
    std::printf("%-28s best base %.5f ensemble %.5f%s\n", c.name.c_str(), best, ensemble,
                ensemble < best ? "" : "  (lost)");
  }
  EXPECT_GE(wins * 10, int(cases.size()) * 9) << wins << " wins of " << cases.size();
}

// Issue 25's per-channel synthetic cases as a regression test: independent per-channel noise
// and members that filter each channel on its own, one of them nonlinear (3x3 box, Gaussian
// σ = 3, 5x5 median; tools/eval/corpus.json's synthetic entries), 128², 4 and 16 spp, three
// seeds: with the default options the ensemble's relMSE is below its best member's.
TEST(EnsembleCombiners, BeatsTheBestMemberOnPerChannelSyntheticCases) {
  const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Regions, 128, 128);
  std::vector<EnsembleMember> members;
  for (const char* name : {"box1", "gauss3", "median5"})
    members.push_back(
        {name, std::shared_ptr<const BaseDenoiser>(synthetic::createSyntheticDenoiser(name))});
  for (int spp : {4, 16})
    for (uint64_t seed : {1, 2, 3}) {
      const synthetic::NoiseModel model{1.0f, spp / 4, 0.0f};
      const Image truth = synthetic::expectedValue(scene, model);
      const EnsembleSources sources =
          sourcesFromBuffers(synthetic::renderBuffers(scene, model, 4, seed));
      const Ensemble ensemble(members, CombineOptions{});
      const EnsembleResult result = ensemble.run(sources);
      double best = std::numeric_limits<double>::infinity();
      for (const BaseOutputs& b : result.bases) best = std::min(best, relMse(b.full, truth));
      const double blend = relMse(result.combined.image, truth);
      EXPECT_LT(blend, best) << spp << " spp, seed " << seed;
      std::printf("per-channel synthetic %3d spp seed %d: best member %.5f ensemble %.5f\n", spp,
                  int(seed), best, blend);
    }
}

TEST(EnsembleCombiners, ConsistentWhenOneBaseIsExact) {
  // One member returns the truth, the others are biased blurs: as the noise goes to 0 the
  // blend's error goes to 0 (quadratically in the noise level), although every other member
  // keeps its bias.
  const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Shadows, 40, 32);
  std::vector<double> errors;
  for (float noise : {0.3f, 0.03f, 0.003f, 0.0003f}) {
    const synthetic::NoiseModel model{noise, 4, 0.0f};
    const SampleBuffers buffers = synthetic::renderBuffers(scene, model, 4, 5);
    const EnsembleSources sources = sourcesFromBuffers(buffers);
    std::vector<EnsembleMember> members;
    members.push_back({"exact", std::shared_ptr<const BaseDenoiser>(
                                    synthetic::createConstantDenoiser("exact", scene.truth))});
    for (const char* name : {"gauss3", "biased", "box1"})
      members.push_back(
          {name, std::shared_ptr<const BaseDenoiser>(synthetic::createSyntheticDenoiser(name))});
    const std::vector<BaseOutputs> bases = runBaseDenoisers(sources, members);
    const CombineResult result = combine(guidesFromSources(sources), pointersTo(bases), {});
    errors.push_back(relMse(result.image, scene.truth));
    EXPECT_GT(relMse(bases[1].full, scene.truth), 1e-3);  // the others stay wrong
  }
  for (size_t k = 1; k < errors.size(); ++k) EXPECT_LT(errors[k], errors[k - 1] * 0.1) << k;
  EXPECT_LT(errors.back(), 1e-7);
}

// Where every base puts a bright blob that neither noisy half shows, the ensemble's result is
// the noisy value (and the half blends the noisy halves); everywhere else the result is the
// blend, bit for bit the same as with the fallback off.
TEST(EnsembleCombiners, NoisyFallbackWhereNoBaseIsPlausible) {
  synthetic::Case c = synthetic::standardCases()[0];
  synthetic::PreparedCase p = synthetic::prepareCase(c, 24, 20);
  const int x = 7, y = 9;
  for (BaseOutputs& b : p.bases)
    for (Image* image : {&b.a, &b.b, &b.full})
      for (int ch = 0; ch < 3; ++ch) (*image)(x, y, ch) += 50.0f;
  CombineOptions onOptions;
  onOptions.mse.noisyFallback = 10;
  const CombineResult on = combine(p.guides, pointersTo(p.bases), onOptions);
  CombineOptions offOptions;
  offOptions.mse.noisyFallback = 0;
  const CombineResult off = combine(p.guides, pointersTo(p.bases), offOptions);
  EXPECT_EQ(on.noisyFallbackPixels, 1u);
  EXPECT_EQ(off.noisyFallbackPixels, 0u);
  for (int py = 0; py < 20; ++py)
    for (int px = 0; px < 24; ++px) {
      const bool here = px == x && py == y;
      EXPECT_EQ(on.noisyFallback(px, py, 0), here ? 1.0f : 0.0f);
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_EQ(on.image(px, py, ch), here ? p.guides.color(px, py, ch) : off.image(px, py, ch));
        EXPECT_EQ(on.imageA(px, py, ch),
                  here ? p.guides.colorA(px, py, ch) : off.imageA(px, py, ch));
      }
    }
  EXPECT_GT(off.image(x, y, 0), p.guides.color(x, y, 0) + 10.0f);  // the blend kept the blob
  // Only the ensemble falls back: the other combiners are the paper's definitions.
  CombineOptions average;
  average.combiner = Combiner::Average;
  EXPECT_TRUE(combine(p.guides, pointersTo(p.bases), average).noisyFallback.empty());
}

// The rest of the guides of a flat, featureless surface whose noisy halves are set: the full
// buffer's mean of the halves, albedo 0.5, normals facing +z.
void completeFlatGuides(EnsembleGuides& guides) {
  const int w = guides.colorA.width(), h = guides.colorA.height();
  guides.color = guides.colorA;
  for (size_t e = 0; e < guides.color.size(); ++e)
    guides.color.data()[e] = 0.5f * (guides.colorA.data()[e] + guides.colorB.data()[e]);
  guides.albedo = Image(w, h, 3, 0.5f);
  guides.normal = Image(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) guides.normal(x, y, 2) = 1.0f;
}

// The interior-at-4-spp pattern (issue 25): a bright region lit through one bounce, where some
// pixels got no sample of the light in either half (x^A = x^B = 0) while every member has spread
// the light there from the lit neighbours. The noisy value is the implausible one, so with the
// default options the result is never darker than every member (at those pixels it is a blend
// or one member, not the black noisy value). Negative control: the old noisy fallback (K = 10)
// darkens them.
TEST(EnsembleCombiners, NeverDarkerThanEveryMemberWhereTheNoisyHalvesMissedTheLight) {
  const int w = 32, h = 24;
  std::mt19937_64 rng(11);
  std::normal_distribution<float> gauss(0.0f, 0.3f);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  EnsembleGuides guides;
  Image truth(w, h, 3, 0.02f);
  for (int y = 0; y < h; ++y)
    for (int x = 8; x < 24; ++x)
      for (int c = 0; c < 3; ++c) truth(x, y, c) = 1.0f;
  int dark = 0;
  guides.colorA = guides.colorB = truth;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool missed = x >= 9 && x < 23 && uniform(rng) < 0.25f;
      dark += missed;
      for (Image* half : {&guides.colorA, &guides.colorB})
        for (int c = 0; c < 3; ++c)
          (*half)(x, y, c) = missed ? 0.0f : std::max(0.0f, truth(x, y, c) * (1.0f + gauss(rng)));
    }
  completeFlatGuides(guides);
  const auto box = [&](const Image& in, int r) {
    Image out(w, h, 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          double sum = 0;
          int count = 0;
          for (int qy = std::max(0, y - r); qy <= std::min(h - 1, y + r); ++qy)
            for (int qx = std::max(0, x - r); qx <= std::min(w - 1, x + r); ++qx)
              sum += in(qx, qy, c), ++count;
          out(x, y, c) = float(sum / count);
        }
    return out;
  };
  std::vector<BaseOutputs> bases;
  for (int r : {1, 2, 3})
    bases.push_back({"box" + std::to_string(r),
                     box(guides.colorA, r),
                     box(guides.colorB, r),
                     box(guides.color, r),
                     {}});
  ASSERT_GT(dark, 20);
  const auto darkerThanEveryMember = [&](const CombineResult& result) {
    int count = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          float least = std::numeric_limits<float>::infinity();
          for (const BaseOutputs& b : bases) least = std::min(least, b.full(x, y, c));
          count += result.image(x, y, c) < least - 1e-5f;
        }
    return count;
  };
  EXPECT_EQ(darkerThanEveryMember(combine(guides, pointersTo(bases), {})), 0);
  CombineOptions oldFallback;
  oldFallback.mse.noisyFallback = 10;
  EXPECT_GT(darkerThanEveryMember(combine(guides, pointersTo(bases), oldFallback)), 0);
}

// The member fallback (the previews' safeguard, K = 2): beside a light, one member spreads it onto
// a dark, well-measured column (6 where both noisy halves say 0.05), another less (1); everywhere
// else the spreading member is exact and the other 10 % off, so every window favours the
// spreading one. With the tests that veto a member off (plausibility, consistency) and windows
// on features alone, the blend takes it on that column; the fallback takes the closer member
// there (one-hot, never the noisy value) and changes nothing where the blend is plausible. The
// window's colour term sees the column as an edge of the members' mean blend (features are flat
// there) and keeps the neighbours' terms out of its windows: the blend alone is then close to
// the closer member.
TEST(EnsembleCombiners, MemberFallbackTakesTheCloserMemberWhereTheBlendIsFarOff) {
  const int w = 32, h = 16, column = 23;
  EnsembleGuides guides;
  Image truth(w, h, 3, 0.05f);
  for (int y = 0; y < h; ++y)
    for (int x = column + 1; x < w; ++x)
      for (int c = 0; c < 3; ++c) truth(x, y, c) = 50.0f;
  std::mt19937_64 rng(5);
  std::normal_distribution<float> gauss(0.0f, 0.05f);
  guides.colorA = guides.colorB = truth;
  for (Image* half : {&guides.colorA, &guides.colorB})
    for (size_t e = 0; e < half->size(); ++e) half->data()[e] *= 1.0f + gauss(rng);
  completeFlatGuides(guides);
  const auto member = [&](const std::string& name, float bias, float spread) {
    Image out = truth;
    for (size_t e = 0; e < out.size(); ++e) out.data()[e] *= bias;
    for (int y = 0; y < h; ++y)
      for (int c = 0; c < 3; ++c) out(column, y, c) = spread;
    return BaseOutputs{name, out, out, out, {}};
  };
  const std::vector<BaseOutputs> bases = {member("closer", 1.1f, 1.0f),
                                          member("spreading", 1.0f, 6.0f)};
  CombineOptions colorEdges;
  colorEdges.mse.plausibility = 0;
  colorEdges.mse.consistency = 0;
  CombineOptions off = colorEdges;
  off.mse.windowSigmaColor = 0;
  CombineOptions on = off;
  on.mse.memberFallback = 2;
  const CombineResult without = combine(guides, pointersTo(bases), off);
  const CombineResult with = combine(guides, pointersTo(bases), on);
  EXPECT_EQ(without.memberFallbackPixels, 0u);
  EXPECT_EQ(with.memberFallbackPixels, size_t(h));
  for (int y = 0; y < h; ++y)
    for (int c = 0; c < 3; ++c) {
      EXPECT_GT(without.image(column, y, c), 3.0f) << y;  // mostly the spreading member
      EXPECT_EQ(with.image(column, y, c), 1.0f) << y;     // the closer member, not the noisy 0.05
    }
  const CombineResult edges = combine(guides, pointersTo(bases), colorEdges);
  for (int y = 0; y < h; ++y)
    for (int c = 0; c < 3; ++c) EXPECT_LT(edges.image(column, y, c), 1.5f) << y;
  // Away from the column (beyond the window's reach of it) nothing changes.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < column - 12; ++x)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(with.image(x, y, c), without.image(x, y, c)) << x;
}

// A small prepared case for the robustness tests.
synthetic::PreparedCase smallCase(uint64_t seed = 3) {
  synthetic::Case c = synthetic::standardCases()[0];
  c.members = {"box1", "gauss3", "nlm", "biased"};
  c.seed = seed;
  return synthetic::prepareCase(c, 24, 20);
}

void scaleAll(synthetic::PreparedCase& p, float factor, int channel = -1) {
  std::vector<Image*> images = {&p.guides.color, &p.guides.colorA, &p.guides.colorB, &p.truth};
  for (BaseOutputs& b : p.bases) images.insert(images.end(), {&b.a, &b.b, &b.full});
  for (Image* image : images)
    for (size_t e = 0; e < image->size(); ++e)
      if (channel < 0 || int(e % 3) == channel) image->data()[e] *= factor;
}

CombineOptions optionsFor(Combiner combiner, SolverKind solver = SolverKind::ActiveSet) {
  CombineOptions o;
  o.combiner = combiner;
  o.solver = solver;
  return o;
}

TEST(EnsembleCombiners, ExtremeMagnitudes) {
  const synthetic::PreparedCase reference = smallCase();
  const CombineResult unscaled =
      combine(reference.guides, pointersTo(reference.bases), {}, &reference.truth);
  for (float factor : {1e-30f, 1e30f}) {
    synthetic::PreparedCase p = reference;
    scaleAll(p, factor);
    for (Combiner combiner : kCombiners)
      for (SolverKind solver : {SolverKind::ActiveSet, SolverKind::Pairwise}) {
        SCOPED_TRACE(std::string(combinerName(combiner)) + " factor " + std::to_string(factor));
        const CombineResult r =
            combine(p.guides, pointersTo(p.bases), optionsFor(combiner, solver), &p.truth);
        expectWeightsOnSimplex(r, combiner != Combiner::OracleUnconstrained);
        expectFinite(r.image);
        expectFinite(r.mseEstimate);
      }
    // The default path does not depend on the unit of radiance.
    const CombineResult r = combine(p.guides, pointersTo(p.bases), {}, &p.truth);
    for (size_t i = 0; i < r.weights.size(); ++i)
      for (size_t e = 0; e < r.weights[i].size(); ++e)
        ASSERT_NEAR(r.weights[i].data()[e], unscaled.weights[i].data()[e], 1e-3)
            << "factor " << factor;
  }
  // One channel a million times brighter than the others.
  synthetic::PreparedCase p = reference;
  scaleAll(p, 1e6f, 1);
  for (Combiner combiner : kCombiners) {
    SCOPED_TRACE(std::string(combinerName(combiner)) + ", one channel ×1e6");
    const CombineResult r = combine(p.guides, pointersTo(p.bases), optionsFor(combiner), &p.truth);
    expectWeightsOnSimplex(r, combiner != Combiner::OracleUnconstrained);
    expectFinite(r.image);
  }
}

TEST(EnsembleCombiners, ZerosEverywhere) {
  synthetic::PreparedCase p = smallCase();
  scaleAll(p, 0.0f);
  for (Combiner combiner : kCombiners) {
    SCOPED_TRACE(std::string(combinerName(combiner)) + ", one channel ×1e6");
    const CombineResult r = combine(p.guides, pointersTo(p.bases), optionsFor(combiner), &p.truth);
    expectWeightsOnSimplex(r, combiner != Combiner::OracleUnconstrained);
    for (float v : r.image.values()) ASSERT_EQ(v, 0.0f);
  }
}

TEST(EnsembleCombiners, FireflyIsNotBlendedIn) {
  // A 1e8 firefly in the noisy half A at one pixel, smeared by the box filter's A output.
  synthetic::PreparedCase p = smallCase();
  const int x = 12, y = 9;
  for (int c = 0; c < 3; ++c) p.guides.colorA(x, y, c) = 1e8f;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      for (int c = 0; c < 3; ++c) p.bases[0].a(x + dx, y + dy, c) += 1e8f / 9;
  for (Combiner combiner : kCombiners) {
    SCOPED_TRACE(std::string(combinerName(combiner)) + ", one channel ×1e6");
    const CombineResult r = combine(p.guides, pointersTo(p.bases), optionsFor(combiner), &p.truth);
    expectWeightsOnSimplex(r, combiner != Combiner::OracleUnconstrained);
    expectFinite(r.image);
    expectFinite(r.mseEstimate);
  }
  // The full-buffer outputs are clean, so the result stays clean.
  const CombineResult r = combine(p.guides, pointersTo(p.bases), {});
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(r.image(x, y, c) - p.truth(x, y, c)), 1.0f);
}

TEST(EnsembleCombiners, NonFiniteBaseOutputGetsZeroWeight) {
  synthetic::PreparedCase p = smallCase();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  p.bases[2].full(5, 5, 0) = nan;
  p.bases[2].a(6, 5, 1) = inf;
  p.bases[2].b(7, 5, 2) = -inf;
  for (int yy = 0; yy < 20; ++yy) p.bases[1].full(20, yy, 1) = nan;  // a whole column
  for (Combiner combiner : kCombiners)
    for (MseForm form : {MseForm::Summed, MseForm::PerChannel}) {
      CombineOptions o = optionsFor(combiner);
      o.mse.form = form;
      const CombineResult r = combine(p.guides, pointersTo(p.bases), o, &p.truth);
      expectWeightsOnSimplex(r, combiner != Combiner::OracleUnconstrained);
      expectFinite(r.image);
      for (int c = 0; c < r.weights[2].channels(); ++c) {
        EXPECT_EQ(r.weights[2](5, 5, c), 0.0f) << combinerName(combiner);
        EXPECT_EQ(r.weights[1](20, 11, c), 0.0f) << combinerName(combiner);
        // The oracles only use the full-buffer outputs.
        if (needsReference(combiner)) continue;
        EXPECT_EQ(r.weights[2](6, 5, c), 0.0f) << combinerName(combiner);
        EXPECT_EQ(r.weights[2](7, 5, c), 0.0f) << combinerName(combiner);
      }
    }
  // Every base non-finite at a pixel: the noisy colour is used.
  for (BaseOutputs& b : p.bases) b.full(3, 3, 0) = nan;
  const CombineResult r = combine(p.guides, pointersTo(p.bases), {});
  EXPECT_EQ(r.image(3, 3, 0), p.guides.color(3, 3, 0));
}

// Issue 26: a member that is NaN everywhere, or over a region, takes weight 0 there while the
// other members' windows still form. All NaN: the result is the four members' result. NaN
// over a region, without the image prior and the outlier cap: deep inside it (beyond the reach
// of the window, 5, and the weight filter, 7) the result is the four members' result, far
// outside it the result without the hole. With them (an image-wide mean and an image-wide
// percentile of the terms, which the hole changes a little everywhere) the four members'
// relMSE deep inside the hole is kept within 2 %.
TEST(EnsembleCombiners, AMissingMemberChangesNothingWhereTheOthersAreFine) {
  synthetic::Case c = synthetic::standardCases()[0];
  c.members = {"box1", "gauss3", "nlm", "biased"};
  const int w = 72, h = 56;
  const synthetic::PreparedCase four = synthetic::prepareCase(c, w, h);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const auto close = [](float a, float b, float tolerance) {
    return std::abs(a - b) <= tolerance * (std::abs(b) + 1e-3f);
  };
  synthetic::PreparedCase five = four;
  BaseOutputs fifth = four.bases[1];
  fifth.name = "fifth";
  for (Image* image : {&fifth.a, &fifth.b, &fifth.full})
    for (float& v : image->values()) v = nan;
  five.bases.push_back(fifth);
  const CombineResult reference = combine(four.guides, pointersTo(four.bases), {});
  const CombineResult allNan = combine(five.guides, pointersTo(five.bases), {});
  int differ = 0;
  for (size_t e = 0; e < reference.image.size(); ++e)
    differ += !close(allNan.image.data()[e], reference.image.data()[e], 1e-4f);
  EXPECT_EQ(differ, 0);
  for (float v : allNan.weights[4].values()) ASSERT_EQ(v, 0.0f);

  // The fifth a good member (a second Gaussian), with a hole.
  five.bases[4] = four.bases[1];
  five.bases[4].name = "fifth";
  const synthetic::PreparedCase whole = five;
  const int x0 = 16, x1 = 56, y0 = 14, y1 = 44, reach = 5 + 7;
  for (Image* image : {&five.bases[4].a, &five.bases[4].b, &five.bases[4].full})
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x)
        for (int ch = 0; ch < 3; ++ch) (*image)(x, y, ch) = nan;
  const auto deep = [&](int x, int y) {
    return x >= x0 + reach && x < x1 - reach && y >= y0 + reach && y < y1 - reach;
  };
  const auto far = [&](int x, int y) {
    return x < x0 - reach || x >= x1 + reach || y < y0 - reach || y >= y1 + reach;
  };
  CombineOptions local;
  local.mse.imagePrior = 0;
  local.mse.outlierCap = 0;
  const CombineResult fourAlone = combine(four.guides, pointersTo(four.bases), local);
  const CombineResult holed = combine(five.guides, pointersTo(five.bases), local);
  const CombineResult unholed = combine(whole.guides, pointersTo(whole.bases), local);
  int inside = 0, insideDiffer = 0, outside = 0, outsideDiffer = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int ch = 0; ch < 3; ++ch) {
        if (deep(x, y)) {
          ++inside;
          insideDiffer += !close(holed.image(x, y, ch), fourAlone.image(x, y, ch), 1e-4f);
        } else if (far(x, y)) {
          ++outside;
          outsideDiffer += !close(holed.image(x, y, ch), unholed.image(x, y, ch), 1e-4f);
        }
      }
  ASSERT_GT(inside, 0);
  ASSERT_GT(outside, 0);
  EXPECT_EQ(insideDiffer, 0) << "of " << inside;
  EXPECT_EQ(outsideDiffer, 0) << "of " << outside;

  const CombineResult holedWithImageWide = combine(five.guides, pointersTo(five.bases), {});
  double errorFour = 0, errorHoled = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int ch = 0; ch < 3 && deep(x, y); ++ch) {
        const double t = four.truth(x, y, ch), d = t * t + 1e-2;
        errorFour += std::pow(reference.image(x, y, ch) - t, 2) / d;
        errorHoled += std::pow(holedWithImageWide.image(x, y, ch) - t, 2) / d;
      }
  std::printf("deep in the hole, relMSE: four members %.6g, five with the hole %.6g\n",
              errorFour / inside, errorHoled / inside);
  EXPECT_LT(errorHoled, 1.02 * errorFour);
}

TEST(EnsembleCombiners, SameResultForAnyThreadCount) {
  const synthetic::PreparedCase p = smallCase();
  for (SolverKind solver : {SolverKind::ActiveSet, SolverKind::Pairwise}) {
    CombineResult one, two;
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
      one = combine(p.guides, pointersTo(p.bases), optionsFor(Combiner::Ensemble, solver));
    }
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
      two = combine(p.guides, pointersTo(p.bases), optionsFor(Combiner::Ensemble, solver));
    }
    EXPECT_TRUE(std::equal(one.image.values().begin(), one.image.values().end(),
                           two.image.values().begin()));
    for (size_t i = 0; i < one.weights.size(); ++i)
      EXPECT_TRUE(std::equal(one.weights[i].values().begin(), one.weights[i].values().end(),
                             two.weights[i].values().begin()));
  }
}

TEST(EnsembleCombiners, AverageIsTheMeanOfTheOutputs) {
  const synthetic::PreparedCase p = smallCase();
  const CombineResult r = combine(p.guides, pointersTo(p.bases), optionsFor(Combiner::Average));
  for (size_t e = 0; e < r.image.size(); ++e) {
    double mean = 0;
    for (const BaseOutputs& b : p.bases) mean += b.full.data()[e];
    ASSERT_NEAR(r.image.data()[e], mean / p.bases.size(), 1e-5);
  }
}

TEST(EnsembleCombiners, OraclePerPixelIsTheProjectionOfTheTruth) {
  // Per channel, per pixel, no filter: the best convex blend of values y_i is the truth clamped
  // to [min y_i, max y_i]; affine blends reach the truth itself.
  const synthetic::PreparedCase p = smallCase();
  CombineOptions o = optionsFor(Combiner::Oracle);
  o.mse.form = MseForm::PerChannel;
  o.mse.windowRadius = 0;
  const CombineResult constrained = combine(p.guides, pointersTo(p.bases), o, &p.truth);
  o.combiner = Combiner::OracleUnconstrained;
  const CombineResult unconstrained = combine(p.guides, pointersTo(p.bases), o, &p.truth);
  for (size_t e = 0; e < p.truth.size(); ++e) {
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (const BaseOutputs& b : p.bases) {
      lo = std::min(lo, b.full.data()[e]);
      hi = std::max(hi, b.full.data()[e]);
    }
    const float r = p.truth.data()[e];
    ASSERT_NEAR(constrained.image.data()[e], std::clamp(r, lo, hi), 1e-4 * (1 + std::abs(r)));
    if (hi - lo > 1e-3f) {
      ASSERT_NEAR(unconstrained.image.data()[e], r, 1e-3 * (1 + std::abs(r)));
    }
  }
}

TEST(EnsembleCombiners, OneHotPicksTheLeastEstimatedError) {
  const synthetic::PreparedCase p = smallCase();
  CombineOptions o = optionsFor(Combiner::OnehotPost);
  o.filter.enabled = false;
  o.mse.windowRadius = 0;
  o.mse.form = MseForm::PerChannel;
  const CombineResult r = combine(p.guides, pointersTo(p.bases), o);
  const MseEstimator estimator(p.guides, pointersTo(p.bases), o.mse);
  for (int y = 0; y < 20; y += 3)
    for (int x = 0; x < 24; x += 5) {
      const PixelMse m = estimator.at(x, y);
      for (int c = 0; c < 3; ++c) {
        int best = 0;
        for (int i = 1; i < int(p.bases.size()); ++i)
          if (m.h[size_t(c)](i, i) < m.h[size_t(c)](best, best)) best = i;
        EXPECT_EQ(r.weights[size_t(best)](x, y, c), 1.0f);
        EXPECT_EQ(r.image(x, y, c), p.bases[size_t(best)].full(x, y, c));
      }
    }
  // With the filter the pre/post variants blend, still on the simplex.
  for (Combiner combiner : {Combiner::OnehotPre, Combiner::OnehotPost})
    expectWeightsOnSimplex(combine(p.guides, pointersTo(p.bases), optionsFor(combiner)));
}

TEST(EnsembleCombiners, EstimatedMseMatchesTheDefinition) {
  // ½[(z^A − x^B)² + (z^B − x^A)²] − ½(x^A − x^B)² from the A/B blends.
  const synthetic::PreparedCase p = smallCase();
  const CombineResult r = combine(p.guides, pointersTo(p.bases), {});
  for (size_t e = 0; e < r.image.size(); e += 7) {
    const double zA = r.imageA.data()[e], zB = r.imageB.data()[e];
    const double xA = p.guides.colorA.data()[e], xB = p.guides.colorB.data()[e];
    EXPECT_NEAR(r.mseEstimate.data()[e],
                0.5 * ((zA - xB) * (zA - xB) + (zB - xA) * (zB - xA) - (xA - xB) * (xA - xB)),
                1e-5 * (1 + xA * xA + xB * xB));
  }
  // Averaged over the image it tracks the true error of the half blends.
  double estimated = 0, actual = 0;
  for (size_t e = 0; e < r.image.size(); ++e) {
    estimated += r.mseEstimate.data()[e];
    const double t = p.truth.data()[e];
    actual += 0.5 * (std::pow(r.imageA.data()[e] - t, 2) + std::pow(r.imageB.data()[e] - t, 2));
  }
  EXPECT_NEAR(estimated, actual, 0.5 * actual);
}

TEST(EnsembleCombiners, RejectsInconsistentInputs) {
  synthetic::PreparedCase p = smallCase();
  EXPECT_THROW(combine(p.guides, pointersTo(p.bases), optionsFor(Combiner::Oracle)), Error);
  std::vector<BaseOutputs> duplicated = {p.bases[0], p.bases[0]};
  EXPECT_THROW(combine(p.guides, pointersTo(duplicated), {}), Error);
  std::vector<BaseOutputs> wrongSize = {p.bases[0]};
  wrongSize[0].b = Image(5, 5, 3);
  EXPECT_THROW(combine(p.guides, pointersTo(wrongSize), {}), Error);
  std::vector<BaseOutputs> many;
  for (int i = 0; i < kMaxDenoisers + 1; ++i) {
    many.push_back(p.bases[0]);
    many.back().name = "copy" + std::to_string(i);
  }
  EXPECT_THROW(combine(p.guides, pointersTo(many), {}), Error);
  EXPECT_THROW(combine(p.guides, {}, {}), Error);
  EXPECT_THROW(parseCombiner("best"), Error);
  EXPECT_THROW(parseSolver("newton"), Error);
  EXPECT_EQ(parseCombiner("onehot-pre"), Combiner::OnehotPre);
}

}  // namespace
}  // namespace chorus
