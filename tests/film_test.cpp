// The film's Welford statistics against a two-pass computation, dropping of non-finite samples,
// and "merging sub-buffers = accumulating their samples together".
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "denoise/buffers/buffers_exr.h"
#include "renderer/integrator/film.h"

namespace chorus::render {
namespace {

PathSample randomSample(std::mt19937& rng) {
  std::exponential_distribution<float> radiance(1.0f);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  PathSample s;
  s.L = {radiance(rng) * 100.0f, radiance(rng), radiance(rng) + 1000.0f};
  s.albedo = {unit(rng), unit(rng), unit(rng)};
  s.normal = {unit(rng) - 0.5f, unit(rng), -unit(rng)};
  s.depth = 10.0f + unit(rng);
  s.visibility = unit(rng) < 0.3f ? 1.0f : 0.0f;
  return s;
}

std::vector<float> flatten(const PathSample& s) {
  return {s.L.r,      s.L.g,      s.L.b,      s.albedo.r, s.albedo.g,  s.albedo.b,
          s.normal.x, s.normal.y, s.normal.z, s.depth,    s.visibility};
}

std::vector<float> pixelValues(const SubBuffer& sub, int x, int y, bool variance) {
  std::vector<float> v;
  for (Quantity q : kAllQuantities) {
    const Image& image = variance ? sub.get(q).varianceOfMean : sub.get(q).mean;
    for (int c = 0; c < image.channels(); ++c) v.push_back(image.at(x, y, c));
  }
  return v;
}

TEST(Film, WelfordMatchesTwoPassStatisticsPerSubBuffer) {
  std::mt19937 rng(7);
  const int splits = 4, spp = 37;
  Film film(3, 2, splits);
  std::vector<std::vector<PathSample>> kept(splits);
  PixelAccumulator pixel;
  for (int i = 0; i < spp; ++i) {
    const PathSample s = randomSample(rng);
    ASSERT_TRUE(pixel.add(i % splits, s));
    kept[size_t(i % splits)].push_back(s);
  }
  film.store(2, 1, pixel);
  const SampleBuffers buffers = film.release();
  ASSERT_EQ(buffers.splitCount(), splits);
  for (int k = 0; k < splits; ++k) {
    const auto& samples = kept[size_t(k)];
    const double n = double(samples.size());
    EXPECT_EQ(buffers.sub(k).sampleCount.at(2, 1, 0), float(n));
    const std::vector<float> mean = pixelValues(buffers.sub(k), 2, 1, false);
    const std::vector<float> variance = pixelValues(buffers.sub(k), 2, 1, true);
    for (size_t c = 0; c < mean.size(); ++c) {
      double sum = 0;
      for (const PathSample& s : samples) sum += flatten(s)[c];
      const double m = sum / n;
      double squares = 0;
      for (const PathSample& s : samples) squares += (flatten(s)[c] - m) * (flatten(s)[c] - m);
      const double varianceOfMean = squares / (n - 1) / n;
      EXPECT_NEAR(mean[c], m, 1e-5 * std::max(1.0, std::abs(m))) << "k " << k << " c " << c;
      EXPECT_NEAR(variance[c], varianceOfMean, 1e-4 * std::max(1e-6, varianceOfMean))
          << "k " << k << " c " << c;
    }
    // Untouched pixels stay zero with no samples.
    EXPECT_EQ(buffers.sub(k).sampleCount.at(0, 0, 0), 0.0f);
    EXPECT_EQ(buffers.sub(k).color.mean.at(0, 0, 0), 0.0f);
  }
}

TEST(Film, NonFiniteSamplesAreDroppedNotAccumulated) {
  PixelAccumulator pixel;
  PathSample good;
  good.L = Rgb(2.0f);
  PathSample nan = good, inf = good, badFeature = good;
  nan.L.g = std::nanf("");
  inf.L.b = std::numeric_limits<float>::infinity();
  badFeature.depth = std::nanf("");
  EXPECT_TRUE(pixel.add(0, good));
  EXPECT_FALSE(pixel.add(0, nan));
  EXPECT_FALSE(pixel.add(0, inf));
  EXPECT_FALSE(pixel.add(0, badFeature));
  EXPECT_TRUE(pixel.add(0, good));
  Film film(1, 1, 1);
  film.store(0, 0, pixel);
  const SampleBuffers b = film.release();
  EXPECT_EQ(b.sub(0).sampleCount.at(0, 0, 0), 2.0f);
  EXPECT_EQ(b.sub(0).color.mean.at(0, 0, 1), 2.0f);
  EXPECT_EQ(b.sub(0).color.varianceOfMean.at(0, 0, 1), 0.0f);
}

TEST(Film, MergingSubBuffersEqualsAccumulatingTogether) {
  std::mt19937 rng(11);
  const int width = 4, height = 3;
  Film split(width, height, 4), single(width, height, 1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      PixelAccumulator a, b;
      const int spp = 5 + x + 3 * y;  // uneven counts per sub-buffer
      for (int i = 0; i < spp; ++i) {
        const PathSample s = randomSample(rng);
        a.add(i % 4, s);
        b.add(0, s);
      }
      split.store(x, y, a);
      single.store(x, y, b);
    }
  const SampleBuffers splitBuffers = split.release(), singleBuffers = single.release();
  const SubBuffer merged = splitBuffers.part(BufferPart::Full);
  const SubBuffer& together = singleBuffers.sub(0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      EXPECT_EQ(merged.sampleCount.at(x, y, 0), together.sampleCount.at(x, y, 0));
      const auto m1 = pixelValues(merged, x, y, false), m2 = pixelValues(together, x, y, false);
      const auto v1 = pixelValues(merged, x, y, true), v2 = pixelValues(together, x, y, true);
      for (size_t c = 0; c < m1.size(); ++c) {
        EXPECT_NEAR(m1[c], m2[c], 2e-5f * std::max(1.0f, std::abs(m2[c])));
        EXPECT_NEAR(v1[c], v2[c], 1e-4f * std::max(1e-6f, v2[c]));
      }
    }
}

// A film that records fewer planes stores the same bits in those it records and leaves the others
// empty.
TEST(Film, RecordsOnlyThePlanesAskedForWithTheSameBits) {
  const BufferPlanes planes = BufferPlanes::colorOnly()
                                  .with(Quantity::Normal, Plane::Mean)
                                  .with(Quantity::Depth, Plane::Variance);
  std::mt19937 rng(5);
  Film all(3, 2, 2), some(3, 2, 2, planes);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      PixelAccumulator pixel;
      for (int i = 0; i < 7; ++i) pixel.add(i % 2, randomSample(rng));
      all.store(x, y, pixel);
      some.store(x, y, pixel);
    }
  const SampleBuffers a = all.release(), s = some.release();
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(s.sub(k).planes(), planes);
    EXPECT_TRUE(s.sub(k).albedo.mean.empty());
    EXPECT_TRUE(s.sub(k).visibility.mean.empty());
    EXPECT_TRUE(s.sub(k).normal.varianceOfMean.empty());
    for (Quantity q : kAllQuantities)
      for (bool variance : {false, true}) {
        const Image& kept = variance ? s.sub(k).get(q).varianceOfMean : s.sub(k).get(q).mean;
        const Image& full = variance ? a.sub(k).get(q).varianceOfMean : a.sub(k).get(q).mean;
        if (kept.empty()) continue;
        EXPECT_TRUE(std::equal(kept.values().begin(), kept.values().end(), full.values().begin(),
                               full.values().end()))
            << quantityName(q) << (variance ? " variance" : "");
      }
    EXPECT_TRUE(std::equal(s.sub(k).sampleCount.values().begin(),
                           s.sub(k).sampleCount.values().end(),
                           a.sub(k).sampleCount.values().begin()));
  }
}

TEST(Film, MovingBuffersIntoExrLayersGivesTheSameLayersAsCopying) {
  std::mt19937 rng(19);
  Film film(3, 2, 4);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      PixelAccumulator pixel;
      for (int i = 0; i < 9; ++i) pixel.add(i % 4, randomSample(rng));
      film.store(x, y, pixel);
    }
  SampleBuffers buffers = film.release();
  const std::vector<ExrLayer> copied = sampleBuffersToLayers(buffers);
  const std::vector<ExrLayer> moved = sampleBuffersToLayers(std::move(buffers));
  ASSERT_EQ(copied.size(), moved.size());
  for (size_t i = 0; i < copied.size(); ++i) {
    EXPECT_EQ(copied[i].name, moved[i].name);
    ASSERT_TRUE(copied[i].image.sameShape(moved[i].image)) << copied[i].name;
    EXPECT_TRUE(std::equal(copied[i].image.values().begin(), copied[i].image.values().end(),
                           moved[i].image.values().begin()))
        << copied[i].name;
  }
}

}  // namespace
}  // namespace chorus::render
