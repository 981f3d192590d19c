// SampleBuffers: merging sub-buffers equals accumulating their raw samples together, and the
// denoiser inputs are built from the documented quarters.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "common/error.h"

#include "denoise/buffers/buffers_exr.h"
#include "denoise/buffers/sample_buffers.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

// Mean and variance of the mean of raw samples, computed directly (two-pass, double).
std::pair<double, double> stats(const std::vector<double>& samples) {
  const double n = double(samples.size());
  double mean = 0;
  for (double s : samples) mean += s / n;
  double m2 = 0;
  for (double s : samples) m2 += (s - mean) * (s - mean);
  return {mean, n >= 2 ? m2 / (n * (n - 1)) : 0.0};
}

struct RawBuffers {
  SampleBuffers buffers;
  // (sub-buffer, pixel, quantity, channel) → samples
  std::map<std::tuple<int, int, int, int>, std::vector<double>> samples;
};

RawBuffers makeRaw(int w, int h, int K) {
  RawBuffers raw;
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.5, 2.0);
  std::vector<SubBuffer> subs;
  for (int k = 0; k < K; ++k) {
    SubBuffer sub = SubBuffer::zeros(w, h);
    for (int p = 0; p < w * h; ++p) {
      const int n = (p + k) % 5;  // unequal counts, including 0 and 1
      sub.sampleCount.data()[p] = float(n);
      for (int qi = 0; qi < int(kAllQuantities.size()); ++qi) {
        const Quantity q = kAllQuantities[size_t(qi)];
        for (int c = 0; c < channelCount(q); ++c) {
          auto& s = raw.samples[{k, p, qi, c}];
          for (int i = 0; i < n; ++i) s.push_back(noise(rng));
          const auto [mean, var] = n > 0 ? stats(s) : std::pair<double, double>{0, 0};
          sub.get(q).mean.data()[p * channelCount(q) + c] = float(mean);
          sub.get(q).varianceOfMean.data()[p * channelCount(q) + c] = float(var);
        }
      }
    }
    subs.push_back(std::move(sub));
  }
  raw.buffers = SampleBuffers(std::move(subs));
  return raw;
}

void expectMergeMatchesRaw(const RawBuffers& raw, const std::vector<int>& indices) {
  const SubBuffer merged = raw.buffers.merge(indices);
  const int pixels = raw.buffers.width() * raw.buffers.height();
  for (int p = 0; p < pixels; ++p) {
    for (int qi = 0; qi < int(kAllQuantities.size()); ++qi) {
      const Quantity q = kAllQuantities[size_t(qi)];
      for (int c = 0; c < channelCount(q); ++c) {
        std::vector<double> all;
        for (int k : indices) {
          const auto& s = raw.samples.at({k, p, qi, c});
          all.insert(all.end(), s.begin(), s.end());
        }
        if (all.empty()) continue;
        const auto [mean, var] = stats(all);
        EXPECT_NEAR(merged.get(q).mean.data()[p * channelCount(q) + c], mean, 1e-5)
            << "pixel " << p << " " << quantityName(q);
        EXPECT_NEAR(merged.get(q).varianceOfMean.data()[p * channelCount(q) + c], var,
                    1e-5 * (1 + var))
            << "pixel " << p << " " << quantityName(q);
      }
      EXPECT_EQ(merged.sampleCount.data()[p], [&] {
        double n = 0;
        for (int k : indices) n += double(raw.samples.at({k, p, 0, 0}).size());
        return float(n);
      }());
    }
  }
}

TEST(SampleBuffers, MergeMatchesStatisticsOfRawSamples) {
  const RawBuffers raw = makeRaw(4, 3, 4);
  expectMergeMatchesRaw(raw, {0, 1});
  expectMergeMatchesRaw(raw, {2, 3});
  expectMergeMatchesRaw(raw, {0, 1, 2, 3});
  expectMergeMatchesRaw(raw, {3, 0, 2});
}

// Two parts take a shorter path through merge(); adding a third part without samples sends
// the same data through the general loop, which must give the same values.
TEST(SampleBuffers, TwoPartMergeEqualsTheGeneralMerge) {
  const RawBuffers raw = makeRaw(37, 29, 2);
  const SubBuffer none = SubBuffer::zeros(37, 29);
  const SubBuffer two = merge({&raw.buffers.sub(0), &raw.buffers.sub(1)});
  const SubBuffer general = merge({&raw.buffers.sub(0), &raw.buffers.sub(1), &none});
  for (Quantity q : kAllQuantities)
    for (const auto& [fast, slow] :
         {std::pair{&two.get(q).mean, &general.get(q).mean},
          std::pair{&two.get(q).varianceOfMean, &general.get(q).varianceOfMean}})
      for (size_t e = 0; e < fast->size(); ++e)
        ASSERT_EQ(fast->data()[e], slow->data()[e]) << quantityName(q) << " element " << e;
}

TEST(SampleBuffers, InputsUseTheDocumentedQuarters) {
  const RawBuffers raw = makeRaw(4, 3, 4);
  const DenoiseInput a = raw.buffers.input(BufferPart::HalfA);
  ASSERT_TRUE(a.halves.has_value());
  EXPECT_EQ(a.halves->at(0).color.mean.values()[5], raw.buffers.sub(0).color.mean.values()[5]);
  EXPECT_EQ(a.halves->at(1).color.mean.values()[5], raw.buffers.sub(1).color.mean.values()[5]);
  const DenoiseInput b = raw.buffers.input(BufferPart::HalfB);
  EXPECT_EQ(b.halves->at(0).color.mean.values()[7], raw.buffers.sub(2).color.mean.values()[7]);
  const DenoiseInput full = raw.buffers.input(BufferPart::Full);
  ASSERT_TRUE(full.halves.has_value());
  EXPECT_EQ(full.halves->at(1).color.mean.values()[3],
            raw.buffers.merge({2, 3}).color.mean.values()[3]);

  const RawBuffers two = makeRaw(2, 2, 2);
  EXPECT_FALSE(two.buffers.input(BufferPart::HalfA).halves.has_value());
  EXPECT_TRUE(two.buffers.input(BufferPart::Full).halves.has_value());
}

TEST(SampleBuffers, RenderExrLayoutRoundTrips) {
  const RawBuffers raw = makeRaw(5, 4, 4);
  test::TempDir dir;
  writeExr(dir / "render.exr", sampleBuffersToLayers(raw.buffers));
  const SampleBuffers back = sampleBuffersFromLayers(readExr(dir / "render.exr"), "render.exr");
  ASSERT_EQ(back.splitCount(), 4);
  for (int k = 0; k < 4; ++k)
    for (Quantity q : kAllQuantities) {
      EXPECT_EQ(back.sub(k).get(q).mean.values()[3], raw.buffers.sub(k).get(q).mean.values()[3]);
      EXPECT_EQ(back.sub(k).get(q).varianceOfMean.values()[2],
                raw.buffers.sub(k).get(q).varianceOfMean.values()[2]);
    }
  // The default layer is the full-buffer colour; the rest of the full buffer is not stored (it
  // is the merge of the sub-buffers).
  EXPECT_EQ(readExrLayer(dir / "render.exr").values()[4],
            raw.buffers.part(BufferPart::Full).color.mean.values()[4]);
  const std::vector<ExrLayer> layers = readExr(dir / "render.exr");
  EXPECT_EQ(layers.size(), 1 + 4 * 11u);  // per sub-buffer: 5 means, 5 variances, the count
  EXPECT_EQ(findLayer(layers, "albedo"), nullptr);
  EXPECT_EQ(findLayer(layers, "colorVariance"), nullptr);
  EXPECT_THROW(sampleBuffersFromLayers({{"", Image(2, 2, 3)}}, "x.exr"), Error);
}

// The buffers with only `planes` (the others emptied).
SampleBuffers withPlanes(const SampleBuffers& buffers, BufferPlanes planes) {
  std::vector<SubBuffer> subs = buffers.subBuffers();
  for (SubBuffer& sub : subs)
    for (Quantity q : kAllQuantities) {
      if (!planes.has(q, Plane::Mean)) sub.get(q).mean = Image();
      if (!planes.has(q, Plane::Variance)) sub.get(q).varianceOfMean = Image();
    }
  return SampleBuffers(std::move(subs));
}

bool sameBits(const Image& a, const Image& b) {
  return a.sameSize(b) && std::equal(a.values().begin(), a.values().end(), b.values().begin());
}

TEST(SampleBuffers, PlanesNameWhatIsHeldAndAVarianceComesWithItsMean) {
  EXPECT_EQ(BufferPlanes::all().list(),
            "albedo, albedo variance, normal, normal variance, depth, depth variance, "
            "visibility, visibility variance");
  EXPECT_EQ(BufferPlanes::colorOnly().list(), "");
  const BufferPlanes p = BufferPlanes::colorOnly().with(Quantity::Depth, Plane::Variance);
  EXPECT_TRUE(p.has(Quantity::Depth, Plane::Mean));
  EXPECT_EQ(p.list(), "depth, depth variance");
  EXPECT_TRUE(BufferPlanes::all().contains(p));
  EXPECT_FALSE(p.contains(BufferPlanes::all()));
  EXPECT_EQ(BufferPlanes::all().minus(p).names().size(), 6u);
  EXPECT_EQ(SubBuffer::zeros(3, 2, p).planes(), p);
  EXPECT_TRUE(SubBuffer::zeros(3, 2, p).visibility.mean.empty());
  EXPECT_EQ(SubBuffer::zeros(3, 2).planes(), BufferPlanes::all());
}

// Sub-buffers holding fewer planes merge and round-trip through render.exr to the same bits in
// the planes they hold.
TEST(SampleBuffers, BuffersWithFewerPlanesMergeAndRoundTripToTheSameBits) {
  const RawBuffers raw = makeRaw(6, 5, 4);
  const BufferPlanes planes = BufferPlanes::colorOnly()
                                  .with(Quantity::Albedo, Plane::Mean)
                                  .with(Quantity::Depth, Plane::Variance);
  const SampleBuffers some = withPlanes(raw.buffers, planes);
  const SubBuffer fullAll = raw.buffers.part(BufferPart::Full);
  const SubBuffer fullSome = some.part(BufferPart::Full);
  EXPECT_EQ(fullSome.planes(), planes);
  for (Quantity q : {Quantity::Color, Quantity::Albedo, Quantity::Depth})
    EXPECT_TRUE(sameBits(fullAll.get(q).mean, fullSome.get(q).mean)) << quantityName(q);
  for (Quantity q : {Quantity::Color, Quantity::Depth})
    EXPECT_TRUE(sameBits(fullAll.get(q).varianceOfMean, fullSome.get(q).varianceOfMean));
  EXPECT_TRUE(sameBits(fullAll.sampleCount, fullSome.sampleCount));

  test::TempDir dir;
  for (int k : {1, 4}) {
    const SampleBuffers buffers =
        k == 4 ? some : SampleBuffers(std::vector<SubBuffer>{some.sub(0)});
    const auto file = dir / ("k" + std::to_string(k) + ".exr");
    writeExr(file, sampleBuffersToLayers(buffers));
    const std::vector<ExrLayer> layers = readExr(file);
    const std::string prefix = k == 4 ? "sub0." : "";
    EXPECT_NE(findLayer(layers, prefix + "albedo"), nullptr);
    EXPECT_EQ(findLayer(layers, prefix + "albedoVariance"), nullptr);
    EXPECT_EQ(findLayer(layers, prefix + "visibility"), nullptr);
    const SampleBuffers back = sampleBuffersFromLayers(layers, file);
    ASSERT_EQ(back.splitCount(), k);
    for (int s = 0; s < k; ++s) {
      EXPECT_EQ(back.sub(s).planes(), planes);
      for (Quantity q : kAllQuantities) {
        EXPECT_TRUE(sameBits(back.sub(s).get(q).mean, buffers.sub(s).get(q).mean));
        EXPECT_TRUE(
            sameBits(back.sub(s).get(q).varianceOfMean, buffers.sub(s).get(q).varianceOfMean));
      }
    }
  }
  // Sub-buffers that differ in planes cannot merge.
  std::vector<SubBuffer> mixed = {raw.buffers.sub(0), some.sub(1)};
  EXPECT_THROW(SampleBuffers(std::move(mixed)).part(BufferPart::Full), std::invalid_argument);
}

TEST(SampleBuffers, ReadingRefusesAVarianceWithoutItsMeanAndSubBuffersThatDiffer) {
  const RawBuffers raw = makeRaw(3, 2, 2);
  std::vector<ExrLayer> layers = sampleBuffersToLayers(raw.buffers);
  std::erase_if(layers, [](const ExrLayer& l) { return l.name == "sub1.depth"; });
  try {
    sampleBuffersFromLayers(layers, "r.exr");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "r.exr: layer 'sub1.depthVariance' without 'sub1.depth'");
  }
  std::erase_if(layers, [](const ExrLayer& l) { return l.name == "sub1.depthVariance"; });
  try {
    sampleBuffersFromLayers(layers, "r.exr");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "r.exr: sub-buffers hold different layers");
  }
  std::erase_if(layers, [](const ExrLayer& l) { return l.name == "sub0.colorVariance"; });
  EXPECT_THROW(sampleBuffersFromLayers(layers, "r.exr"), Error);
}

}  // namespace
}  // namespace chorus
