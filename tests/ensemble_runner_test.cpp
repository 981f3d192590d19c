// The Ensemble runner: runs every member on the full buffer and on half A and half B or the four
// held-out inputs (exactly what running the denoiser on those inputs gives), combines, reports
// every stage's time, refuses members that cannot run on the given sub-buffers, and is
// deterministic; MemberRunner, which prepares an input once for the members sharing a guard,
// gives each member exactly its own run's output.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "common/error.h"
#include "denoise/base/outlier_guard.h"
#include "denoise/metrics/metrics.h"
#include "denoise/pipeline/ensemble.h"
#include "denoise/pipeline/held_out_inputs.h"
#include "denoise/pipeline/member_runner.h"
#include "tests/support/synthetic_cases.h"

namespace chorus {
namespace {

// A plain box filter: the test-only base denoiser.
class BoxDenoiser : public BaseDenoiser {
 public:
  explicit BoxDenoiser(int radius) : radius_(radius) {}
  std::string name() const override { return "box" + std::to_string(radius_); }
  DenoiserRequirements requirements() const override { return {}; }
  Image run(const DenoiseInput& input) const override {
    const Image& in = input.whole.color.mean;
    Image out(in.width(), in.height(), 3);
    for (int y = 0; y < in.height(); ++y)
      for (int x = 0; x < in.width(); ++x)
        for (int c = 0; c < 3; ++c) {
          double sum = 0;
          int count = 0;
          for (int qy = std::max(0, y - radius_); qy <= std::min(in.height() - 1, y + radius_);
               ++qy)
            for (int qx = std::max(0, x - radius_); qx <= std::min(in.width() - 1, x + radius_);
                 ++qx, ++count)
              sum += in(qx, qy, c);
          out(x, y, c) = float(sum / count);
        }
    return out;
  }

 private:
  int radius_;
};

// Needs two halves of its input (like NFOR): averages them, so its output equals the whole.
class HalvesDenoiser : public BaseDenoiser {
 public:
  std::string name() const override { return "halves"; }
  DenoiserRequirements requirements() const override { return {false, true}; }
  Image run(const DenoiseInput& input) const override {
    if (!input.halves) throw Error("HalvesDenoiser: no halves");
    Image out = (*input.halves)[0].color.mean;
    const Image& other = (*input.halves)[1].color.mean;
    for (size_t e = 0; e < out.size(); ++e)
      out.data()[e] = 0.5f * (out.data()[e] + other.data()[e]);
    return out;
  }
};

SampleBuffers buffers(int splits, uint64_t seed = 9) {
  const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Regions, 30, 22);
  return synthetic::renderBuffers(scene, {1.0f, 4, 0.0f}, splits, seed);
}

std::vector<EnsembleMember> boxMembers() {
  return {{"box1", std::make_shared<BoxDenoiser>(1)}, {"box3", std::make_shared<BoxDenoiser>(3)}};
}

bool sameImage(const Image& a, const Image& b) {
  return a.sameShape(b) && std::equal(a.values().begin(), a.values().end(), b.values().begin());
}

CombineOptions withEstimate(MseEstimate estimate) {
  CombineOptions options;
  options.mse.estimate = estimate;
  return options;
}

std::set<std::string> stagesOf(const EnsembleResult& result) {
  std::set<std::string> stages;
  for (const StageTime& t : result.times) {
    stages.insert(t.stage);
    EXPECT_GE(t.seconds, 0.0);
  }
  return stages;
}

TEST(EnsembleRunner, RunsEveryMemberOnHalfAHalfBAndFull) {
  const SampleBuffers b = buffers(4);
  const Ensemble ensemble(boxMembers(), withEstimate(MseEstimate::Halves));
  const EnsembleResult result = ensemble.run(b);
  ASSERT_EQ(result.bases.size(), 2u);
  const BoxDenoiser box1(1), box3(3);
  EXPECT_EQ(result.bases[0].name, "box1");
  EXPECT_TRUE(sameImage(result.bases[0].a, box1.run(b.input(BufferPart::HalfA))));
  EXPECT_TRUE(sameImage(result.bases[0].b, box1.run(b.input(BufferPart::HalfB))));
  EXPECT_TRUE(sameImage(result.bases[1].full, box3.run(b.input(BufferPart::Full))));
  // The guides are the noisy halves, and the combination is combine() on those outputs.
  EXPECT_TRUE(sameImage(result.guides.colorA, b.part(BufferPart::HalfA).color.mean));
  EXPECT_TRUE(sameImage(result.guides.colorB, b.part(BufferPart::HalfB).color.mean));
  const CombineResult direct = combine(result.guides, pointersTo(result.bases), ensemble.options());
  EXPECT_TRUE(sameImage(result.combined.image, direct.image));
  EXPECT_TRUE(result.bases[0].heldOut.empty());
  // Every stage is timed.
  const std::set<std::string> stages = stagesOf(result);
  for (const char* stage : {"box1/A", "box1/B", "box1/full", "box3/A", "box3/B", "box3/full",
                            "bases", "solve", "filter", "blend"})
    EXPECT_TRUE(stages.count(stage)) << stage;
}

// The quarters estimate (the default) on K = 4: the four held-out runs only; each member's
// blended output is their mean (for a linear filter, its run on the full buffer up to float
// rounding); the blend's A/B images are left out and its estimated MSE comes from the folds.
// The extrapolated estimate runs everything.
TEST(EnsembleRunner, TheQuartersEstimateRunsTheHeldOutInputsInsteadOfTheHalves) {
  const SampleBuffers b = buffers(4);
  const Ensemble ensemble(boxMembers(), {});
  const EnsembleResult result = ensemble.run(b);
  const std::vector<DenoiseInput> heldOut = heldOutInputs(sourcesFromBuffers(b));
  const BoxDenoiser box3(3);
  ASSERT_EQ(result.bases[1].heldOut.size(), 4u);
  for (size_t k = 0; k < 4; ++k)
    EXPECT_TRUE(sameImage(result.bases[1].heldOut[k], box3.run(heldOut[k]))) << k;
  const Image fullRun = box3.run(b.input(BufferPart::Full));
  for (size_t e = 0; e < fullRun.size(); ++e)
    ASSERT_NEAR(result.bases[1].full.data()[e], fullRun.data()[e],
                1e-5f * (1.0f + std::abs(fullRun.data()[e])));
  EXPECT_FALSE(result.bases[0].hasHalfRuns());
  EXPECT_TRUE(result.combined.imageA.empty() && result.combined.imageB.empty());
  EXPECT_TRUE(result.combined.mseEstimate.sameShape(result.combined.image));
  const std::set<std::string> stages = stagesOf(result);
  EXPECT_EQ(stages.count("box1/A") + stages.count("box3/B") + stages.count("box1/full"), 0u);
  for (const char* stage :
       {"box1/without-q0", "box3/without-q3", "bases", "solve", "filter", "blend"})
    EXPECT_TRUE(stages.count(stage)) << stage;
  // Combining the same runs with the halves estimate is refused in one line.
  EXPECT_THROW(
      combine(result.guides, pointersTo(result.bases), withEstimate(MseEstimate::Extrapolated)),
      Error);

  const EnsembleResult both =
      Ensemble(boxMembers(), withEstimate(MseEstimate::Extrapolated)).run(b);
  EXPECT_TRUE(both.bases[0].hasHalfRuns());
  EXPECT_TRUE(sameImage(both.bases[1].full, fullRun));
  EXPECT_EQ(both.bases[0].heldOut.size(), 4u);
  EXPECT_FALSE(both.combined.imageA.empty());
  // K = 2 has no quarters: the half runs, whatever the estimate asks for.
  const EnsembleResult two = ensemble.run(buffers(2));
  EXPECT_TRUE(two.bases[0].hasHalfRuns());
  EXPECT_TRUE(two.bases[0].heldOut.empty());
}

// At 3 spp quarter 3 holds no samples. The run without quarter 2 then has only quarters 0 and 1:
// they are its halves, instead of (q0 q1 | q3), a half holding nothing, which a member that
// splits its input denoises as an empty image. The other runs keep their split.
TEST(HeldOutInputs, AnEmptyQuarterIsNeverAHalf) {
  SampleBuffers b = buffers(4);
  b.sub(3) = SubBuffer::zeros(b.width(), b.height(), b.sub(0).planes());
  ASSERT_EQ(meanSampleCount(b.sub(3)), 0.0);
  ASSERT_GT(meanSampleCount(b.sub(0)), 0.0);
  const EnsembleSources sources = sourcesFromBuffers(b);
  for (int k = 0; k < 4; ++k) {
    const DenoiseInput input = heldOutInput(sources, k);
    ASSERT_TRUE(input.halves.has_value());
    for (const SubBuffer& half : *input.halves)
      EXPECT_GT(meanSampleCount(half), 0.0) << "without quarter " << k;
    EXPECT_TRUE(sameImage(input.whole.color.mean,
                          merge({&(*input.halves)[0], &(*input.halves)[1]}).color.mean))
        << k;
  }
  const DenoiseInput withoutQ2 = heldOutInput(sources, 2);
  EXPECT_TRUE(sameImage((*withoutQ2.halves)[0].color.mean, b.sub(0).color.mean));
  EXPECT_TRUE(sameImage((*withoutQ2.halves)[1].color.mean, b.sub(1).color.mean));
  // Without quarter 0 the split is the usual one: q1 | q2 q3.
  const DenoiseInput withoutQ0 = heldOutInput(sources, 0);
  EXPECT_TRUE(sameImage((*withoutQ0.halves)[0].color.mean, b.sub(1).color.mean));
  EXPECT_TRUE(sameImage((*withoutQ0.halves)[1].color.mean, b.merge({2, 3}).color.mean));
}

// Progress reports every run once, in order of completion: 0 of N first, then 1 … N, each naming
// a run of the stage times; the same for members run alone.
TEST(EnsembleRunner, ReportsEveryRunsEndToTheProgressCallback) {
  const SampleBuffers b = buffers(4);
  for (const MseEstimate estimate : {MseEstimate::Quarters, MseEstimate::Extrapolated}) {
    std::vector<RunsProgress> reports;
    const EnsembleResult result =
        Ensemble(boxMembers(), withEstimate(estimate))
            .run(sourcesFromBuffers(b), nullptr,
                 [&reports](const RunsProgress& p) { reports.push_back(p); });
    std::set<std::string> runs = stagesOf(result), reported;
    for (const char* notRun : {"bases", "solve", "filter", "blend"}) runs.erase(notRun);
    ASSERT_EQ(reports.size(), runs.size() + 1);  // 8 held-out runs, or 14 with the halves
    EXPECT_EQ(runs.size(), estimate == MseEstimate::Quarters ? 8u : 14u);
    for (size_t i = 0; i < reports.size(); ++i) {
      EXPECT_EQ(reports[i].done, i);
      EXPECT_EQ(reports[i].total, runs.size());
      if (i == 0) {
        EXPECT_TRUE(reports[i].finished.empty());
      } else {
        reported.insert(reports[i].finished);
      }
    }
    EXPECT_EQ(reported, runs);
  }
  std::vector<RunsProgress> alone;
  runMembersAlone(b.input(BufferPart::Full), boxMembers(), nullptr,
                  [&alone](const RunsProgress& p) { alone.push_back(p); });
  ASSERT_EQ(alone.size(), 3u);
  EXPECT_EQ(alone.back().done, 2u);
  EXPECT_EQ(alone.back().total, 2u);
  EXPECT_TRUE(alone[1].finished == "box1/full" || alone[1].finished == "box3/full");
}

// On an image of kFullRunPixels pixels at up to kFullRunSpp samples per pixel the quarters
// estimate also runs each member on the full buffer and blends that run (not the mean of the
// held-out runs); one sample per pixel more and it blends the mean again.
TEST(EnsembleRunner, LargeImagesAtFewSamplesBlendTheFullRun) {
  const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Regions, 256, 128);
  ASSERT_EQ(256L * 128L, kFullRunPixels);
  const std::vector<EnsembleMember> members = {{"box3", std::make_shared<BoxDenoiser>(3)}};
  const Ensemble ensemble(members, {});
  const BoxDenoiser box3(3);
  for (const int perQuarter : {4, 5}) {  // 16 and 20 samples per pixel
    const SampleBuffers b = synthetic::renderBuffers(scene, {1.0f, perQuarter, 0.0f}, 4, 3);
    const EnsembleResult result = ensemble.run(b);
    const bool fullRun = double(4 * perQuarter) <= kFullRunSpp;
    EXPECT_EQ(stagesOf(result).count("box3/full"), fullRun ? 1u : 0u) << perQuarter;
    ASSERT_EQ(result.bases[0].heldOut.size(), 4u);
    const Image expected =
        fullRun ? box3.run(b.input(BufferPart::Full)) : meanOfHeldOutRuns(result.bases[0]);
    EXPECT_TRUE(sameImage(result.bases[0].full, expected)) << perQuarter;
  }
  // Below the size, a run at few samples blends the mean (the rule's other side).
  const synthetic::Scene small = synthetic::makeScene(synthetic::SceneKind::Regions, 255, 128);
  const SampleBuffers b = synthetic::renderBuffers(small, {1.0f, 1, 0.0f}, 4, 3);
  EXPECT_EQ(stagesOf(ensemble.run(b)).count("box3/full"), 0u);
}

// Where the blend takes the full runs (large images at few samples) of members that split their
// own input, or the image has 512 x 256 pixels or more (any members), the weights come from the
// wider window (mse.fullRunWindowRadius); elsewhere mse.windowRadius.
TEST(EnsembleRunner, FullRunsOfMembersThatSplitTheirInputGetTheWiderWindow) {
  const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Regions, 256, 128);
  const synthetic::Scene large = synthetic::makeScene(synthetic::SceneKind::Regions, 512, 256);
  std::vector<EnsembleMember> splitting = boxMembers();
  splitting.push_back({"halves", std::make_shared<HalvesDenoiser>()});
  const auto blendWith = [](const EnsembleResult& result, int radius) {
    CombineOptions o;
    o.mse.windowRadius = radius;
    return combine(result.guides, pointersTo(result.bases), o).image;
  };
  // 4 spp: full runs blended; 20 spp: held-out means (wide only on the large image).
  for (const int perQuarter : {1, 5, -5}) {
    const bool isLarge = perQuarter < 0;
    const SampleBuffers b =
        synthetic::renderBuffers(isLarge ? large : scene, {1.0f, std::abs(perQuarter), 0.0f}, 4, 5);
    for (const bool split : {true, false}) {
      const EnsembleResult result = Ensemble(split ? splitting : boxMembers(), {}).run(b);
      const bool wide = isLarge || (split && perQuarter == 1);
      const MseOptions defaults;
      ASSERT_NE(defaults.windowRadius, defaults.fullRunWindowRadius);
      EXPECT_TRUE(
          sameImage(result.combined.image,
                    blendWith(result, wide ? defaults.fullRunWindowRadius : defaults.windowRadius)))
          << perQuarter << " " << split;
      EXPECT_FALSE(
          sameImage(result.combined.image,
                    blendWith(result, wide ? defaults.windowRadius : defaults.fullRunWindowRadius)))
          << perQuarter << " " << split;
    }
  }
}

// The quarters estimate compares each held-out run with its quarter as rendered: a firefly in
// one quarter stays in that quarter's comparator (the outlier guard's clamps would take ordinary
// bright samples off a one-sample quarter's mean and bias the estimate), while the halves, which
// the halves estimate compares with, keep the guard's clamp.
TEST(EnsembleRunner, TheQuartersAreComparedWithUnguarded) {
  SampleBuffers b = buffers(4);
  // One of quarter 1's four samples at (12, 9) is 1e4: its mean and variance of the mean as
  // those samples give them (1e4 / 4 above the others; (1e4)^2 * 3/16 / 4 ... rounded: 6.25e6).
  b.sub(1).color.mean(12, 9, 0) += 2500.0f;
  b.sub(1).color.varianceOfMean(12, 9, 0) = 6.25e6f;
  const EnsembleGuides guides = guidesFromSources(sourcesFromBuffers(b), true);
  ASSERT_EQ(guides.quarters.size(), 4u);
  for (int k = 0; k < 4; ++k)
    EXPECT_TRUE(sameImage(guides.quarters[size_t(k)], b.sub(k).color.mean)) << k;
  EXPECT_GT(guides.quarters[1](12, 9, 0), 2500.0f);
  EXPECT_LT(guides.colorA(12, 9, 0), 100.0f);  // the half's mean would be above 1250
}

TEST(EnsembleRunner, HalvesOfTheirOwnInputNeedFourSubBuffers) {
  std::vector<EnsembleMember> members = boxMembers();
  members.push_back({"halves", std::make_shared<HalvesDenoiser>()});
  const Ensemble ensemble(members, withEstimate(MseEstimate::Halves));
  // K = 4: the half runs get quarters as their halves.
  const SampleBuffers four = buffers(4);
  const EnsembleResult result = ensemble.run(four);
  EXPECT_TRUE(sameImage(result.bases[2].a, HalvesDenoiser().run(four.input(BufferPart::HalfA))));
  // K = 2: a clear error naming the member.
  try {
    ensemble.run(buffers(2));
    FAIL() << "expected chorus::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'halves' needs two independent halves"),
              std::string::npos)
        << e.what();
  }
  // Members without that need run on K = 2, and on a Tungsten-style input with two halves.
  EXPECT_NO_THROW(Ensemble(boxMembers(), {}).run(buffers(2)));
  const SampleBuffers two = buffers(2);
  const EnsembleSources sources = sourcesFromHalves(two.input(BufferPart::Full));
  EXPECT_TRUE(sameImage(sources.a.whole.color.mean, two.sub(0).color.mean));
  EXPECT_NO_THROW(Ensemble(boxMembers(), {}).run(sources));
  EXPECT_THROW(ensemble.run(sources), Error);
  // One sub-buffer cannot be split at all.
  EXPECT_THROW(Ensemble(boxMembers(), {}).run(buffers(1)), Error);
  // The full buffer's halves may be left out of the sources (chorus render does, to save
  // memory): a run on the full buffer then builds them from the half inputs for its own runs,
  // and every estimate gives the same result as with them held.
  EnsembleSources noFullHalves = sourcesFromBuffers(four);
  noFullHalves.full.halves.reset();
  const Ensemble quarters(members, {});
  EXPECT_TRUE(
      sameImage(quarters.run(noFullHalves).combined.image, quarters.run(four).combined.image));
  const EnsembleResult built = ensemble.run(noFullHalves);
  EXPECT_TRUE(sameImage(built.bases[2].full, result.bases[2].full));
  EXPECT_TRUE(sameImage(built.combined.image, result.combined.image));
}

// Taking the buffers over gives the same inputs as copying them (every image of every part),
// and leaves the full input's halves out only when asked to.
TEST(EnsembleRunner, SourcesTakenOverEqualSourcesCopied) {
  const auto sameSub = [](const SubBuffer& x, const SubBuffer& y) {
    for (Quantity q : kAllQuantities)
      if (!sameImage(x.get(q).mean, y.get(q).mean) ||
          !sameImage(x.get(q).varianceOfMean, y.get(q).varianceOfMean))
        return false;
    return sameImage(x.sampleCount, y.sampleCount);
  };
  for (int splits : {2, 4})
    for (bool halvesOfFull : {true, false}) {
      SCOPED_TRACE("K = " + std::to_string(splits) + (halvesOfFull ? ", halves" : ", none"));
      SampleBuffers taken = buffers(splits);
      const EnsembleSources copied = sourcesFromBuffers(taken);
      const EnsembleSources moved = sourcesFromBuffers(std::move(taken), halvesOfFull);
      EXPECT_EQ(taken.splitCount(), 0);
      EXPECT_TRUE(sameSub(moved.a.whole, copied.a.whole));
      EXPECT_TRUE(sameSub(moved.b.whole, copied.b.whole));
      EXPECT_TRUE(sameSub(moved.full.whole, copied.full.whole));
      EXPECT_EQ(moved.a.halves.has_value(), splits == 4);
      if (splits == 4) {
        EXPECT_TRUE(sameSub((*moved.a.halves)[1], (*copied.a.halves)[1]));
      }
      ASSERT_EQ(moved.full.halves.has_value(), halvesOfFull);
      if (halvesOfFull) {
        EXPECT_TRUE(sameSub((*moved.full.halves)[0], (*copied.full.halves)[0]));
        EXPECT_TRUE(sameSub((*moved.full.halves)[1], (*copied.full.halves)[1]));
      }
    }
  // Which members read halves: NFOR-like ones need them, joint NL-means uses them when present.
  std::vector<EnsembleMember> members = boxMembers();
  EXPECT_FALSE(readsHalves(members));
  members.push_back({"halves", std::make_shared<HalvesDenoiser>()});
  EXPECT_TRUE(readsHalves(members));
  EXPECT_TRUE(readsHalves(membersFromSpecs(std::vector<std::string>{"atrous", "jnlm"})));
  EXPECT_FALSE(readsHalves(membersFromSpecs(std::vector<std::string>{"atrous", "bilateral"})));
}

TEST(EnsembleRunner, RejectsBadMemberLists) {
  EXPECT_THROW(Ensemble({}, {}).run(buffers(4)), Error);
  std::vector<EnsembleMember> twice = {{"box", std::make_shared<BoxDenoiser>(1)},
                                       {"box", std::make_shared<BoxDenoiser>(2)}};
  EXPECT_THROW(Ensemble(twice, {}).run(buffers(4)), Error);
}

TEST(EnsembleRunner, SameResultForAnyThreadCount) {
  const SampleBuffers b = buffers(4);
  EnsembleResult one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = Ensemble(boxMembers(), {}).run(b);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = Ensemble(boxMembers(), {}).run(b);
  }
  EXPECT_TRUE(sameImage(one.combined.image, two.combined.image));
  for (size_t i = 0; i < one.combined.weights.size(); ++i)
    EXPECT_TRUE(sameImage(one.combined.weights[i], two.combined.weights[i]));
}

TEST(EnsembleRunner, BetterThanItsMembersOnANoisyRender) {
  // The box filters' errors differ in space (3×3 keeps edges, 7×7 removes noise): the ensemble
  // beats both against the expected value.
  const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Shadows, 48, 40);
  const synthetic::NoiseModel model{1.0f, 4, 0.0f};
  const SampleBuffers b = synthetic::renderBuffers(scene, model, 4, 3);
  const EnsembleResult result = Ensemble(boxMembers(), {}).run(b);
  const Image truth = synthetic::expectedValue(scene, model);
  const double ensemble = relMse(result.combined.image, truth);
  for (const BaseOutputs& base : result.bases)
    EXPECT_LT(ensemble, relMse(base.full, truth)) << base.name;
}

bool identical(const Image& a, const Image& b) {
  if (!a.sameShape(b)) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a.data()[i] != b.data()[i]) return false;
  return true;
}

TEST(MemberRunner, EveryMemberGetsExactlyItsOwnRunsOutput) {
  // Bright emitters with fireflies, so that the guard clamps values and the preparations for
  // the default guard and for guard=0 differ.
  const synthetic::Scene scene = synthetic::makeScene(synthetic::SceneKind::Hdr, 40, 32);
  const SampleBuffers buffers = synthetic::renderBuffers(scene, {1.0f, 2, 0.03f}, 4, 5);
  const EnsembleSources sources = sourcesFromBuffers(buffers);
  std::vector<EnsembleMember> members =
      membersFromSpecs(std::vector<std::string>{"atrous", "nfor", "atrous:guard=0", "sbf"});
  members.push_back({"box1", synthetic::createSyntheticDenoiser("box1")});  // not guarded

  for (const DenoiseInput& input : {sources.full, heldOutInput(sources, 2)}) {
    ASSERT_GT(guardOutliers(input).clampedValues, 0u);
    const MemberRunner runner(input, members);
    std::vector<Image> shared;
    for (size_t m = 0; m < members.size(); ++m) {
      shared.push_back(runner.run(m));
      EXPECT_TRUE(identical(shared.back(), members[m].denoiser->run(input))) << members[m].label;
    }
    EXPECT_FALSE(identical(shared[0], shared[2])) << "atrous with and without the guard";
  }
}

}  // namespace
}  // namespace chorus
