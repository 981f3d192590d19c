// The safety around every built-in member (denoise/base/guarded_denoiser.h) piece by piece:
// filling NaN/Inf colour, the power-of-two radiance scale, the output's finish, the decorator
// itself; and the two small helpers the writers and NFOR use (output_values.h, local_range.h).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/error.h"
#include "common/image/output_values.h"
#include "denoise/base/filters/local_range.h"
#include "denoise/base/guarded_denoiser.h"
#include "denoise/base/nonfinite_fill.h"
#include "denoise/base/radiance_scale.h"
#include "denoise/base/registry.h"
#include "denoise/pipeline/ensemble_sources.h"
#include "denoise/pipeline/held_out_inputs.h"
#include "tests/support/synthetic_cases.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kMax = std::numeric_limits<float>::max();

SubBuffer constantBuffer(int w, int h, float value) {
  SubBuffer s = SubBuffer::zeros(w, h);
  s.color.mean.fill(value);
  s.color.varianceOfMean.fill(0.01f);
  s.sampleCount.fill(4);
  return s;
}

TEST(NonFiniteFill, HolesTakeTheirNeighboursValues) {
  SubBuffer s = constantBuffer(10, 8, 2.5f);
  s.color.mean(3, 3, 1) = kNan;  // one value
  for (int y = 2; y < 7; ++y)
    for (int x = 5; x < 9; ++x) s.color.mean(x, y, 0) = y == 4 ? -kInf : kNan;  // a block
  EXPECT_EQ(fillNonFiniteColor(s), 1u + 20u);
  for (float v : s.color.mean.values()) EXPECT_EQ(v, 2.5f);
  EXPECT_FLOAT_EQ(s.color.varianceOfMean(6, 4, 0), 0.01f);  // the neighbours' variance
}

TEST(NonFiniteFill, MedianOfTheFiniteNeighbours) {
  SubBuffer s = constantBuffer(3, 3, 0.0f);
  const float values[9] = {1, 2, 3, 4, kNan, 6, 7, 100, 9};
  for (int i = 0; i < 9; ++i) s.color.mean(i % 3, i / 3, 0) = values[i];
  fillNonFiniteColor(s);
  EXPECT_EQ(s.color.mean(1, 1, 0), 6.0f);  // the upper median of {1, 2, 3, 4, 6, 7, 9, 100}
}

TEST(NonFiniteFill, AChannelWithNoFiniteValueBecomesZero) {
  SubBuffer s = constantBuffer(4, 4, kNan);
  fillNonFiniteColor(s);
  for (float v : s.color.mean.values()) EXPECT_EQ(v, 0.0f);
}

TEST(RadianceScale, OrdinaryRadianceIsLeftAlone) {
  DenoiseInput in;
  in.whole = constantBuffer(4, 4, 1000.0f);
  in.whole.color.mean(1, 1, 0) = 1e-4f;
  EXPECT_EQ(radianceScaleExponent(in), 0);
}

TEST(RadianceScale, HugeAndTinyRadianceAreBroughtIntoRange) {
  DenoiseInput huge;
  huge.whole = constantBuffer(4, 4, 3e38f);
  huge.whole.color.varianceOfMean.fill(kMax);
  const int down = radianceScaleExponent(huge);
  EXPECT_GT(down, 0);
  EXPECT_LE(std::ldexp(3e38, -down), std::ldexp(1.0, kMaxRadianceExponent));
  EXPECT_GT(std::ldexp(3e38, -down), std::ldexp(1.0, kMaxRadianceExponent - 1));

  DenoiseInput tiny;
  tiny.whole = constantBuffer(4, 4, 3e-30f);
  tiny.whole.color.varianceOfMean.fill(0.0f);
  const int up = radianceScaleExponent(tiny);
  EXPECT_LT(up, 0);
  const double scaled = std::ldexp(3e-30, -up);
  EXPECT_GE(scaled, 0.5);
  EXPECT_LT(scaled, 1.0);
}

TEST(RadianceScale, PowersOfTwoChangeNoBits) {
  DenoiseInput in;
  in.whole = constantBuffer(5, 5, 0.0f);
  for (size_t i = 0; i < in.whole.color.mean.size(); ++i) {
    in.whole.color.mean.data()[i] = 0.1f + 0.37f * float(i);
    in.whole.color.varianceOfMean.data()[i] = 0.01f * float(i);
  }
  DenoiseInput scaled = in;
  scaleColor(scaled, -37);
  scaleColor(scaled, 37);
  for (size_t i = 0; i < in.whole.color.mean.size(); ++i) {
    EXPECT_EQ(scaled.whole.color.mean.data()[i], in.whole.color.mean.data()[i]);
    EXPECT_EQ(scaled.whole.color.varianceOfMean.data()[i], in.whole.color.varianceOfMean.data()[i]);
  }
  Image image = in.whole.color.mean;
  scaleImage(image, 200);  // beyond float: kept at the largest float
  for (float v : image.values()) EXPECT_EQ(v, kMax);
}

TEST(RadianceScale, SaturatedVariancesUseTheTwoBufferEstimate) {
  // Halves 1e30 · (1 ± 0.1): the variance of the mean is unrepresentable (the film stores
  // FLT_MAX); scaled down, it becomes the two-buffer estimate ¼ (h1 − h2)² in relative form,
  // here exactly ¼ (0.2 · 1e30)² · 2^(−2e) since every pixel is alike.
  DenoiseInput in;
  in.halves =
      std::array<SubBuffer, 2>{constantBuffer(6, 6, 1.1e30f), constantBuffer(6, 6, 0.9e30f)};
  in.whole = constantBuffer(6, 6, 1e30f);
  in.whole.color.varianceOfMean.fill(kMax);
  for (SubBuffer& half : *in.halves) half.color.varianceOfMean.fill(kMax);
  const int e = radianceScaleExponent(in);
  scaleColor(in, -e);
  const double expectedWhole = 0.25 * std::pow(std::ldexp(0.2e30, -e), 2);
  EXPECT_NEAR(in.whole.color.varianceOfMean(3, 3, 0), expectedWhole, 1e-4 * expectedWhole);
  EXPECT_NEAR((*in.halves)[0].color.varianceOfMean(3, 3, 0), 2 * expectedWhole,
              2e-4 * expectedWhole);
}

TEST(FinishOutput, FiniteAndNeverBelowZeroOrTheInput) {
  Image out(4, 1, 1), noisy(4, 1, 1);
  const float outValues[4] = {kNan, -3.0f, -1.0f, kInf};
  const float noisyValues[4] = {0.5f, 2.0f, -2.0f, kNan};
  for (int x = 0; x < 4; ++x) out(x, 0, 0) = outValues[x], noisy(x, 0, 0) = noisyValues[x];
  finishOutput(out, noisy);
  EXPECT_EQ(out(0, 0, 0), 0.5f);   // NaN → the noisy value
  EXPECT_EQ(out(1, 0, 0), 0.0f);   // negative where the input is not → 0
  EXPECT_EQ(out(2, 0, 0), -1.0f);  // a negative input allows down to itself
  EXPECT_EQ(out(3, 0, 0), 0.0f);   // Inf and no finite input → 0
}

TEST(KeepWithinTheSamples, BoundsOnlyWellMeasuredPixels) {
  // Mean 1, standard error 0.1, 16 samples: within 10 standard errors means [0, 2]. Pixel 2 has
  // 4 samples and pixel 3 no variance: what their samples say is too little to bound anything.
  SubBuffer whole = constantBuffer(4, 1, 1.0f);
  whole.sampleCount.fill(16);
  whole.sampleCount(2, 0, 0) = 4;
  whole.color.varianceOfMean(3, 0, 0) = 0.0f;
  Image out(4, 1, 3);
  const float values[4] = {5.0f, -3.0f, 5.0f, 5.0f};
  for (int x = 0; x < 4; ++x) out(x, 0, 0) = out(x, 0, 1) = out(x, 0, 2) = values[x];
  keepWithinTheSamples(out, whole, 10.0);
  EXPECT_NEAR(out(0, 0, 0), 2.0f, 1e-6);  // 0.01f is not exactly 0.01
  EXPECT_NEAR(out(1, 0, 0), 0.0f, 1e-6);
  EXPECT_EQ(out(2, 0, 0), 5.0f);
  EXPECT_EQ(out(3, 0, 0), 5.0f);
  EXPECT_NEAR(out(3, 0, 1), 2.0f, 1e-6);  // the other channels have their variance
}

// 7x7 pixels at 0.1 with standard error 0.1 and 16 samples (a dim surface lit by rare bright
// paths); the centre's samples all missed them: 0.02 with standard error 0.001.
SubBuffer anUnluckyPixel() {
  SubBuffer whole = constantBuffer(7, 7, 0.1f);
  whole.sampleCount.fill(16);
  for (int c = 0; c < 3; ++c) {
    whole.color.mean(3, 3, c) = 0.02f;
    whole.color.varianceOfMean(3, 3, c) = 1e-6f;
  }
  return whole;
}

TEST(KeepWithinTheSamples, AnUnluckyPixelMayRiseToItsNeighbours) {
  // Its neighbours' variance is that of a path found by p = 0.09 / (0.09 + 16 * 0.09) = 1/17 of
  // the samples (channels summed), which all 16 miss with probability (16/17)^16 = 0.38. Its
  // own samples would hold a member's 2 down to 0.02 + 10 * 0.001; bounded by its
  // neighbourhood's standard error (0.02 + 10 * 0.1) but no higher than its typical neighbour,
  // it gets 0.1. The other pixels keep their own bound, 0.1 + 10 * 0.1.
  SubBuffer whole = anUnluckyPixel();
  Image out(7, 7, 3);
  out.fill(2.0f);
  keepWithinTheSamples(out, whole, 10.0);
  EXPECT_NEAR(out(3, 3, 0), 0.1f, 1e-6);
  EXPECT_NEAR(out(2, 3, 0), 1.1f, 1e-6);
}

TEST(KeepWithinTheSamples, ADarkLineRisesNoHigherThanItsTypicalNeighbour) {
  // The same pixel on a dark row (a contact shadow: 0.02) with dim pixels above it (0.05) and the
  // lit ones below (0.1): its neighbours' median is 0.05, so a member's 2 is held there, not at
  // 0.1 where the bright side would take it.
  SubBuffer whole = anUnluckyPixel();
  for (int x = 0; x < 7; ++x)
    for (int c = 0; c < 3; ++c) {
      whole.color.mean(x, 3, c) = 0.02f;
      for (int y = 0; y < 3; ++y) whole.color.mean(x, y, c) = 0.05f;
    }
  Image out(7, 7, 3);
  out.fill(2.0f);
  keepWithinTheSamples(out, whole, 10.0);
  EXPECT_NEAR(out(3, 3, 0), 0.05f, 1e-6);
}

TEST(KeepWithinTheSamples, APixelBesideWhatMostSamplesFindKeepsItsOwnBound) {
  // Neighbours at 1 with standard error 0.1 from 16 samples are lit by paths most samples find
  // (p = 1 / (1 + 16 * 0.01), summed over the channels alike: all 16 miss with probability
  // 0.138^16 = 2e-14 < kUnluckyPixel): the darker centre is dark, not unlucky, and its own
  // samples bound it: 0.5 + 10 * 0.001.
  SubBuffer whole = anUnluckyPixel();
  for (int y = 0; y < 7; ++y)
    for (int x = 0; x < 7; ++x)
      for (int c = 0; c < 3; ++c) whole.color.mean(x, y, c) = x == 3 && y == 3 ? 0.5f : 1.0f;
  Image out(7, 7, 3);
  out.fill(2.0f);
  keepWithinTheSamples(out, whole, 10.0);
  EXPECT_NEAR(out(3, 3, 0), 0.51f, 1e-6);
}

TEST(KeepWithinTheSamples, AFireflyNextDoorLoosensNothing) {
  // A well-measured pixel at 1 (standard error 0.1) beside one firefly pixel whose variance is
  // 1e6: the median of the neighbourhood is still 0.01, so a member that spread the firefly's
  // 50 onto it is held at 1 + 10 * 0.1 = 2, as without the firefly.
  SubBuffer whole = constantBuffer(7, 7, 1.0f);
  whole.sampleCount.fill(16);
  for (int c = 0; c < 3; ++c) {
    whole.color.mean(4, 3, c) = 1000.0f;
    whole.color.varianceOfMean(4, 3, c) = 1e6f;
  }
  Image out(7, 7, 3);
  out.fill(50.0f);
  keepWithinTheSamples(out, whole, 10.0);
  EXPECT_NEAR(out(3, 3, 0), 2.0f, 1e-5);
  EXPECT_EQ(out(4, 3, 0), 50.0f);  // the firefly's own bound: 1000 +- 1e4
}

TEST(GuardedDenoiser, PartialRunsAreBoundedWhereTheFullRunIs) {
  // Four quarters of a flat image at 1 and a member that answers 5 everywhere. At 4 samples per
  // quarter (a 16-spp render) the full run is bounded by its 16 samples, and the ensemble's
  // held-out (12 samples) and half runs (8), which stand in for it, by their own samples as
  // well: 1 + 10 standard errors of the input's mean. At 2 per quarter nothing is bounded.
  for (const float perQuarter : {4.0f, 2.0f}) {
    std::vector<SubBuffer> quarters(4, constantBuffer(6, 5, 1.0f));
    for (SubBuffer& q : quarters) q.sampleCount.fill(perQuarter);
    const SampleBuffers buffers(quarters);
    const EnsembleSources sources = sourcesFromBuffers(buffers);
    std::vector<DenoiseInput> inputs = heldOutInputs(sources);
    inputs.push_back(sources.a);
    inputs.push_back(sources.full);
    Image five(6, 5, 3);
    five.fill(5.0f);
    const GuardedDenoiser member(synthetic::createConstantDenoiser("five", five));
    for (const DenoiseInput& in : inputs) {
      const double bound = 1.0 + 10.0 * std::sqrt(double(in.whole.color.varianceOfMean(2, 2, 0)));
      ASSERT_LT(bound, 4.0);
      const float expected = perQuarter == 4.0f ? float(bound) : 5.0f;
      EXPECT_NEAR(member.run(in)(2, 2, 0), expected, 1e-5)
          << in.whole.sampleCount(2, 2, 0) << " samples";
    }
  }
}

TEST(KeepNoiseFreeMisses, OnlyExactMissesKeepTheirInput) {
  // Four pixels of an input at 0.25 (variance 0, 4 samples): (0) a miss, kept; (1) a miss with
  // noise, (2) a hit (depth 3), (3) a miss seen by one sample only: left to the member.
  SubBuffer whole = constantBuffer(4, 1, 0.25f);
  whole.color.varianceOfMean.fill(0.0f);
  whole.color.varianceOfMean(1, 0, 2) = 1e-3f;
  whole.depth.mean(2, 0, 0) = 3.0f;
  whole.sampleCount(3, 0, 0) = 1.0f;
  Image out(4, 1, 3);
  out.fill(7.0f);
  keepNoiseFreeMisses(out, whole);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(out(0, 0, c), 0.25f);
    for (int x = 1; x < 4; ++x) EXPECT_EQ(out(x, 0, c), 7.0f) << x;
  }
}

TEST(GuardedDenoiser, OnePixelHoleInASilhouetteStaysBlack) {
  // A bright surface (depth 2, radiance 10 ± noise) with one pixel that every sample saw as a
  // miss of a black background: a blurring member must not fill it.
  SubBuffer whole = constantBuffer(16, 16, 10.0f);
  whole.depth.mean.fill(2.0f);
  whole.albedo.mean.fill(0.5f);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) whole.color.mean(x, y, 1) += 0.5f * float((x * 7 + y * 3) % 5);
  for (int c = 0; c < 3; ++c) {
    whole.color.mean(8, 8, c) = whole.color.varianceOfMean(8, 8, c) = 0.0f;
    whole.albedo.mean(8, 8, c) = 0.0f;
  }
  whole.depth.mean(8, 8, 0) = 0.0f;
  DenoiseInput in;
  in.whole = whole;
  const Image out = createDenoiser("atrous")->run(in);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(out(8, 8, c), 0.0f);
  EXPECT_GT(out(7, 8, 0), 5.0f);
}

TEST(GuardedDenoiser, RegistryMembersKeepTheirNamesAndRequirements) {
  for (const DenoiserEntry& entry : builtinDenoisers()) {
    ParamMap none;
    const auto plain = entry.create(none);
    const auto guarded = createDenoiser(entry.name);
    EXPECT_EQ(guarded->name(), plain->name());
    EXPECT_EQ(guarded->requirements().halves, plain->requirements().halves);
    EXPECT_EQ(guarded->requirements().features, plain->requirements().features);
  }
  EXPECT_THROW(createDenoiser("atrous:guard=-1"), Error);
  EXPECT_NO_THROW(createDenoiser("atrous:spread=12"));
  for (const char* bad : {"atrous:spread=0", "atrous:spread=33"}) {
    try {
      createDenoiser(bad);
      ADD_FAILURE() << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("spread must be"), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(createDenoiser("atrous:peak=0"));
  try {
    createDenoiser("atrous:peak=-1");
    ADD_FAILURE() << "peak=-1";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("peak must be"), std::string::npos) << e.what();
  }
}

TEST(OutputValues, RepairsAndCounts) {
  Image radiance(3, 2, 1);
  const float values[6] = {kNan, kInf, -kInf, -0.5f, 0.0f, 7.0f};
  for (int i = 0; i < 6; ++i) radiance.data()[i] = values[i];
  Image signedCopy = radiance;
  const OutputRepairs r = repairForOutput(radiance);
  EXPECT_EQ(r.nonFinite, 3u);
  EXPECT_EQ(r.negative, 1u);
  const float expected[6] = {0.0f, kMax, 0.0f, 0.0f, 0.0f, 7.0f};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(radiance.data()[i], expected[i]) << i;
  const OutputRepairs s = repairForOutput(signedCopy, true);
  EXPECT_EQ(s.nonFinite, 3u);
  EXPECT_EQ(s.negative, 0u);
  EXPECT_EQ(signedCopy.data()[2], -kMax);
  EXPECT_EQ(signedCopy.data()[3], -0.5f);
}

TEST(LocalRange, MatchesBruteForce) {
  Image image = test::randomImage(13, 9, 2, 7, -1.0f, 1.0f);
  image(4, 4, 1) = kNan;       // skipped
  for (int radius : {2, 9}) {  // 9: windows wider than the image is tall
    const LocalRange range = localRange(image, radius);
    for (int y = 0; y < 9; ++y)
      for (int x = 0; x < 13; ++x)
        for (int c = 0; c < 2; ++c) {
          float lo = kInf, hi = -kInf;
          for (int qy = std::max(0, y - radius); qy <= std::min(8, y + radius); ++qy)
            for (int qx = std::max(0, x - radius); qx <= std::min(12, x + radius); ++qx)
              if (std::isfinite(image(qx, qy, c)))
                lo = std::min(lo, image(qx, qy, c)), hi = std::max(hi, image(qx, qy, c));
          ASSERT_EQ(range.lo(x, y, c), lo) << radius;
          ASSERT_EQ(range.hi(x, y, c), hi) << radius;
        }
  }
}

}  // namespace
}  // namespace chorus
