// The outlier guard (denoise/base/outlier_guard.h) on sub-buffers built from explicit samples,
// so that every expected value is the plain arithmetic of those samples: a lone firefly becomes
// the mean of the pixel's other samples, a firefly with peers keeps its energy in the window, a
// value its own samples confirm is kept, ordinary noise is never touched, and the whole is the
// merge of the guarded halves.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "denoise/base/outlier_guard.h"

namespace chorus {
namespace {

using Samples = std::function<std::vector<double>(int x, int y)>;

// A sub-buffer whose grey colour at (x, y) has exactly the given samples (mean, variance of the
// mean M2 / (n (n − 1)) and count, as the film computes them).
SubBuffer fromSamples(int w, int h, const Samples& samples) {
  SubBuffer s = SubBuffer::zeros(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::vector<double> v = samples(x, y);
      const double n = double(v.size());
      double mean = 0, m2 = 0;
      for (double e : v) mean += e / n;
      for (double e : v) m2 += (e - mean) * (e - mean);
      for (int c = 0; c < 3; ++c) {
        s.color.mean(x, y, c) = float(mean);
        s.color.varianceOfMean(x, y, c) = n >= 2 ? float(m2 / (n * (n - 1))) : 0.0f;
      }
      s.sampleCount(x, y, 0) = float(n);
    }
  return s;
}

// Four samples per pixel: 1 ± 0.5 in a fixed pseudo-random pattern.
std::vector<double> ordinary(int x, int y, uint32_t seed) {
  std::mt19937 rng(seed + uint32_t(x * 7919 + y * 104729));
  std::uniform_real_distribution<double> u(0.5, 1.5);
  return {u(rng), u(rng), u(rng), u(rng)};
}

DenoiseInput wholeOnly(const SubBuffer& s) {
  DenoiseInput in;
  in.whole = s;
  return in;
}

double channelSum(const Image& image) {
  double sum = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) sum += image(x, y, 0);
  return sum;
}

// The guard clamps outliers of `s` and keeps the image's sum to 1e-5, and the peaks are gone: no
// value above a fifth of one outlier's contribution to its pixel's mean.
void expectSpreadKeepingTheEnergy(const SubBuffer& s, float contribution) {
  const GuardedInput g = guardOutliers(wholeOnly(s));
  EXPECT_GT(g.clampedValues, 0u);
  const double before = channelSum(s.color.mean), after = channelSum(g.input.whole.color.mean);
  EXPECT_NEAR(after, before, 1e-5 * before);
  float largest = 0;
  for (float v : g.input.whole.color.mean.values()) largest = std::max(largest, v);
  EXPECT_LT(largest, 0.2f * contribution);
}

TEST(OutlierGuard, OrdinaryNoiseIsNeverTouched) {
  const SubBuffer s = fromSamples(24, 24, [](int x, int y) { return ordinary(x, y, 1); });
  const GuardedInput g = guardOutliers(wholeOnly(s));
  EXPECT_EQ(g.clampedValues, 0u);
  EXPECT_EQ(g.input.whole.color.mean.values().size(), s.color.mean.values().size());
  for (size_t i = 0; i < s.color.mean.size(); ++i)
    ASSERT_EQ(g.input.whole.color.mean.data()[i], s.color.mean.data()[i]);
}

TEST(OutlierGuard, LoneFireflyBecomesTheMeanOfTheOtherSamples) {
  // Pixel (12, 12): three samples of 1 and one of 1e6. With the other samples alike, the mean
  // without the largest sample is exactly 1 (withoutLargestSample with the neighbours' spread
  // subtracted stays within that spread of it).
  const SubBuffer s = fromSamples(24, 24, [](int x, int y) {
    if (x == 12 && y == 12) return std::vector<double>{1, 1, 1, 1e6};
    return ordinary(x, y, 2);
  });
  const GuardedInput g = guardOutliers(wholeOnly(s));
  EXPECT_EQ(g.clampedValues, 3u);  // one per channel
  EXPECT_NEAR(g.input.whole.color.mean(12, 12, 0), 1.0, 0.3);
  EXPECT_LT(g.input.whole.color.varianceOfMean(12, 12, 0), 1.0f);
  // Nothing else moved: the firefly had no peers, so its excess is dropped, not spread.
  EXPECT_EQ(g.input.whole.color.mean(11, 12, 0), s.color.mean(11, 12, 0));
}

TEST(OutlierGuard, ConfirmedExcessIsKept) {
  // A bright pixel whose four samples all agree (a small light seen directly): its own samples
  // confirm it, however far above its neighbours it is.
  const SubBuffer s = fromSamples(24, 24, [](int x, int y) {
    if (x == 5 && y == 9) return std::vector<double>{900, 1000, 1100, 1000};
    return ordinary(x, y, 3);
  });
  EXPECT_EQ(guardOutliers(wholeOnly(s)).clampedValues, 0u);
}

TEST(OutlierGuard, ManySamplesOfTheTailAreConsistent) {
  // The same heavy tail (one sample in 8 at 200, the rest at 1) at 8 and at 128 samples per
  // pixel: at 8 the pixels holding a tail sample stand out and are guarded; at 128 every pixel
  // holds about 16 of them, its own samples confirm its mean and nothing changes.
  auto tail = [](int n) {
    return [n](int x, int y) {
      std::vector<double> v(size_t(n), 1.0);
      const int hits = n >= 128 ? n / 8 : ((x * 3 + y * 5) % 17 == 0 ? 1 : 0);
      for (int i = 0; i < hits; ++i) v[size_t(i)] = 200.0;
      return v;
    };
  };
  EXPECT_GT(guardOutliers(wholeOnly(fromSamples(32, 32, tail(8)))).clampedValues, 0u);
  EXPECT_EQ(guardOutliers(wholeOnly(fromSamples(32, 32, tail(128)))).clampedValues, 0u);
}

TEST(OutlierGuard, FirefliesWithPeersKeepTheirEnergy) {
  // A caustic: one pixel in 11 of a 16×16 block holds one sample of 300 among four of ~1 (so a
  // 5×5 neighbourhood holds about two others). Those outliers have peers; their excess is
  // spread, so the image's sum is kept.
  const SubBuffer s = fromSamples(40, 40, [](int x, int y) {
    std::vector<double> v = ordinary(x, y, 4);
    if (x >= 12 && x < 28 && y >= 12 && y < 28 && (3 * x + 5 * y) % 11 == 0) v[0] = 300.0;
    return v;
  });
  expectSpreadKeepingTheEnergy(s, 300.0f / 4.0f);
}

// A wall lit only by rare paths (docs/outliers.md's corridor at 4 spp): every sample is 0 but
// one of the four at every fifth pixel across and down, which is 200. No 5 × 5 neighbourhood
// holds another, so the RMS test alone dropped them all and the wall went black; the spread
// window holds several on the same surface, filling an area, so each is spread: the wall keeps
// its light and loses its peaks.
SubBuffer sparseTail(const std::function<float(int x, int y)>& depth) {
  SubBuffer s = fromSamples(48, 48, [](int x, int y) {
    std::vector<double> v = {0, 0, 0, 0};
    if (x % 5 == 0 && y % 5 == 0) v[0] = 200.0;
    return v;
  });
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) s.depth.mean(x, y, 0) = depth(x, y);
  return s;
}

TEST(OutlierGuard, ASparseTailOverAnAreaKeepsItsEnergy) {
  const SubBuffer s = sparseTail([](int, int) { return 2.0f; });
  expectSpreadKeepingTheEnergy(s, 200.0f / 4.0f);
}

// The same samples, but every 5 × 5 block is a surface of its own depth (1.5 times or less
// than a third of every other's): no sample has a peer on its surface, so
// each is dropped, as a lone firefly is.
TEST(OutlierGuard, TailSamplesOnOtherSurfacesAreNotPeers) {
  const SubBuffer s =
      sparseTail([](int x, int y) { return std::pow(1.5f, float(x / 5 + 10 * (y / 5))); });
  const GuardedInput g = guardOutliers(wholeOnly(s));
  EXPECT_GT(g.clampedValues, 0u);
  EXPECT_LT(channelSum(g.input.whole.color.mean), 1e-3 * channelSum(s.color.mean));
}

// Tail samples along a line (every third pixel of row 20: a light's edge, a glint) have peers in
// the spread window, but on a line, not over an area: their excess belongs to the line, and
// spread over the window it became a halo beside it. It is dropped; the rows beside it keep
// their values.
TEST(OutlierGuard, ALineOfTailSamplesIsNotSpreadBesideIt) {
  const SubBuffer s = fromSamples(48, 48, [](int x, int y) {
    std::vector<double> v = {0.01, 0.01, 0.01, 0.01};
    if (y == 20 && x % 3 == 0) v[0] = 200.0;
    return v;
  });
  const GuardedInput g = guardOutliers(wholeOnly(s));
  EXPECT_GT(g.clampedValues, 0u);
  for (int x = 0; x < 48; ++x) {
    EXPECT_EQ(g.input.whole.color.mean(x, 18, 0), s.color.mean(x, 18, 0)) << x;
    EXPECT_EQ(g.input.whole.color.mean(x, 22, 0), s.color.mean(x, 22, 0)) << x;
  }
}

// spread=R (the previews take 12): the same caustic's excess over a wider window keeps the same
// energy in a fainter, wider blob.
TEST(OutlierGuard, AWiderSpreadKeepsTheEnergyInAFainterBlob) {
  const SubBuffer s = fromSamples(40, 40, [](int x, int y) {
    std::vector<double> v = ordinary(x, y, 4);
    if (x >= 12 && x < 28 && y >= 12 && y < 28 && (3 * x + 5 * y) % 11 == 0) v[0] = 300.0;
    return v;
  });
  OutlierGuardOptions wide;
  wide.spreadRadius = 12;
  const Image narrowOut = guardOutliers(wholeOnly(s)).input.whole.color.mean;
  const Image wideOut = guardOutliers(wholeOnly(s), wide).input.whole.color.mean;
  const double before = channelSum(s.color.mean);
  EXPECT_NEAR(channelSum(wideOut), before, 1e-5 * before);
  float narrowPeak = 0, widePeak = 0;
  for (float v : narrowOut.values()) narrowPeak = std::max(narrowPeak, v);
  for (float v : wideOut.values()) widePeak = std::max(widePeak, v);
  EXPECT_LT(widePeak, 0.8f * narrowPeak);
  // Nine pixels left of the block: beyond radius 6 of every outlier, within 12 of some.
  EXPECT_EQ(narrowOut(3, 20, 0), s.color.mean(3, 20, 0));
  EXPECT_GT(wideOut(3, 20, 0), s.color.mean(3, 20, 0));
}

// A rare path found twice in a dark, well-sampled region (issue 25's glass-caustics at 256 spp):
// 64 samples per pixel of 0.001 and 0.003 (level 0.002), and at (30, 30) and (31, 30) one of
// the 64 is 3000 (a mean of ~46.9, peers of each other). At radius 6 their excess made a blob
// peaking at ~1.7, 800 times the level; spread until the peak is about the neighbourhood's
// level plus noise, the radius reaches its limit of 32 (σ 16): each blob then peaks at about
// 46.9 / (2π 16²) ≈ 0.029, the two together below 0.08 with the level. The energy stays.
TEST(OutlierGuard, ARarePathInTheDarkIsSpreadThin) {
  const SubBuffer s = fromSamples(64, 64, [](int x, int y) {
    std::vector<double> v(64);
    for (size_t i = 0; i < v.size(); ++i) v[i] = i % 2 ? 0.003 : 0.001;
    if (y == 30 && (x == 30 || x == 31)) v[0] = 3000.0;
    return v;
  });
  OutlierGuardOptions fixed;
  fixed.spreadPeak = 0;
  const GuardedInput thin = guardOutliers(wholeOnly(s)), blob = guardOutliers(wholeOnly(s), fixed);
  ASSERT_EQ(thin.clampedValues, 6u);  // two pixels, three channels
  const double before = channelSum(s.color.mean);
  EXPECT_NEAR(channelSum(thin.input.whole.color.mean), before, 1e-5 * before);
  EXPECT_NEAR(channelSum(blob.input.whole.color.mean), before, 1e-5 * before);
  float thinPeak = 0, blobPeak = 0;
  for (float v : thin.input.whole.color.mean.values()) thinPeak = std::max(thinPeak, v);
  for (float v : blob.input.whole.color.mean.values()) blobPeak = std::max(blobPeak, v);
  EXPECT_GT(blobPeak, 1.0f);
  EXPECT_LT(thinPeak, 0.08f);
  EXPECT_GT(thinPeak, 0.04f);
  // 20 pixels away: beyond radius 6, well inside 32.
  EXPECT_EQ(blob.input.whole.color.mean(10, 30, 0), s.color.mean(10, 30, 0));
  EXPECT_GT(thin.input.whole.color.mean(10, 30, 0), s.color.mean(10, 30, 0) + 0.005f);
}

// Where the neighbourhood is lit (samples of 1 ± 0.5, a sparse caustic of one sample of 30 in
// four) a blob of radius 6 peaks well below its level, and where the level is 0 (the only light
// comes in sparse samples, which the median does not measure) nothing says it stands out: both
// are spread exactly as with the fixed radius.
TEST(OutlierGuard, WhereTheNeighbourhoodIsLitOrSparseTheRadiusStays) {
  for (const double floorValue : {1.0, 0.0}) {
    const SubBuffer s = fromSamples(40, 40, [floorValue](int x, int y) {
      std::vector<double> v = floorValue > 0 ? ordinary(x, y, 7) : std::vector<double>(4, 0.0);
      if (x >= 12 && x < 28 && y >= 12 && y < 28 && (3 * x + 5 * y) % 11 == 0) v[0] = 30.0;
      return v;
    });
    OutlierGuardOptions fixed;
    fixed.spreadPeak = 0;
    const GuardedInput g = guardOutliers(wholeOnly(s)), f = guardOutliers(wholeOnly(s), fixed);
    ASSERT_GT(g.clampedValues, 0u) << floorValue;
    for (size_t i = 0; i < s.color.mean.size(); ++i)
      ASSERT_EQ(g.input.whole.color.mean.data()[i], f.input.whole.color.mean.data()[i])
          << floorValue << " at " << i;
    // …and the excess was spread (not dropped): the energy stays.
    const double before = channelSum(s.color.mean);
    EXPECT_NEAR(channelSum(g.input.whole.color.mean), before, 1e-5 * before) << floorValue;
  }
}

// The caustic of FirefliesWithPeersKeepTheirEnergy on a surface that ends at x = 20; beyond it
// every sample misses a black background.
SubBuffer causticUpToAnEdge(float backgroundDepth) {
  SubBuffer s = fromSamples(40, 40, [](int x, int y) {
    if (x >= 20) return std::vector<double>{0, 0, 0, 0};
    std::vector<double> v = ordinary(x, y, 4);
    if (x >= 12 && y >= 12 && y < 28 && (3 * x + 5 * y) % 11 == 0) v[0] = 300.0;
    return v;
  });
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) s.depth.mean(x, y, 0) = x < 20 ? 2.0f : backgroundDepth;
  return s;
}

double sumLeftOf(const Image& image, int edge) {
  double sum = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < edge; ++x) sum += image(x, y, 0);
  return sum;
}

TEST(OutlierGuard, SpreadStaysOnTheOutliersSurface) {
  // With the background at depth 0 (a miss) nothing is spread onto it: it stays black. With
  // the background at the surface's depth 2 (one surface, black beyond x = 20) the detection is
  // the same (it reads colour only) and every share of the spread lands somewhere: the image
  // keeps its energy. The surface then receives exactly what it receives in the first case, so
  // there the shares that would cross the depth edge were dropped, not moved onto the surface.
  const SubBuffer edge = causticUpToAnEdge(0.0f), flat = causticUpToAnEdge(2.0f);
  const GuardedInput g = guardOutliers(wholeOnly(edge)), one = guardOutliers(wholeOnly(flat));
  ASSERT_GT(g.clampedValues, 0u);
  EXPECT_EQ(g.clampedValues, one.clampedValues);
  for (int y = 0; y < 40; ++y)
    for (int x = 20; x < 40; ++x) ASSERT_LT(g.input.whole.color.mean(x, y, 0), 1e-12f) << x << y;
  const double before = channelSum(flat.color.mean);
  EXPECT_NEAR(channelSum(one.input.whole.color.mean), before, 1e-5 * before);
  const double onSurface = sumLeftOf(one.input.whole.color.mean, 20);
  EXPECT_NEAR(sumLeftOf(g.input.whole.color.mean, 20), onSurface, 1e-5 * onSurface);
  EXPECT_LT(onSurface, 0.999 * before);  // some of the spread did cross the edge
}

// causticUpToAnEdge(2) (one depth everywhere) with the pixels beyond x = 20 of another albedo
// or facing another way: a thin light set into a wall (black albedo at the wall's depth), a
// highlight on a curved mirror (the same depth, other normals).
SubBuffer causticBesideAnotherMaterial(bool albedoDiffers, bool normalDiffers) {
  SubBuffer s = causticUpToAnEdge(2.0f);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) {
      const bool beyond = x >= 20;
      for (int c = 0; c < 3; ++c) {
        s.albedo.mean(x, y, c) = beyond && albedoDiffers ? 0.0f : 0.75f;
        s.normal.mean(x, y, c) = c == (beyond && normalDiffers ? 0 : 2) ? 1.0f : 0.0f;
      }
    }
  return s;
}

TEST(OutlierGuard, SpreadStaysOnTheOutliersMaterialAndOrientation) {
  // One depth everywhere: beyond x = 20 receives part of the spread when albedo and normal
  // match (the image keeps its energy), and little or nothing when either differs; the surface
  // receives the same either way (the other side's shares are dropped, not moved onto it).
  const SubBuffer same = causticBesideAnotherMaterial(false, false);
  const GuardedInput one = guardOutliers(wholeOnly(same));
  const double before = channelSum(same.color.mean);
  const double onSurface = sumLeftOf(one.input.whole.color.mean, 20);
  const double beyond = channelSum(one.input.whole.color.mean) - onSurface;
  ASSERT_GT(one.clampedValues, 0u);
  EXPECT_NEAR(onSurface + beyond, before, 1e-5 * before);
  ASSERT_GT(beyond, 1.0);  // the spread did reach the other side
  for (const auto& [albedo, normal] : {std::pair{true, false}, std::pair{false, true}}) {
    const GuardedInput g = guardOutliers(wholeOnly(causticBesideAnotherMaterial(albedo, normal)));
    EXPECT_EQ(g.clampedValues, one.clampedValues) << albedo << normal;
    const double surface = sumLeftOf(g.input.whole.color.mean, 20);
    EXPECT_NEAR(surface, onSurface, 1e-5 * onSurface) << albedo << normal;
    // A black albedo beside 0.75 is a relative difference of 1: at most e^−2 of the shares.
    EXPECT_LT(channelSum(g.input.whole.color.mean) - surface, (albedo ? 0.14 : 0.01) * beyond)
        << albedo << normal;
  }
}

TEST(OutlierGuard, ASparkleOnAThinSurfaceIsNotSmearedAlongIt) {
  // A one-pixel-wide strip at depth 2 (x = 20) across a background at depth 10 that holds a
  // caustic (peers for every outlier), and one sparkle on the strip: a sample of 300 among
  // four of ~1 at (20, 20). Its excess (~74) may not be given to the strip's few pixels: a
  // Gaussian share of the whole 13×13 window is at most 1/Σg ≈ 1/48 of it, so no strip pixel
  // gets more than ~1.6 over its level (concentrated on the strip's 13 pixels it was ~10).
  SubBuffer s = fromSamples(40, 40, [](int x, int y) {
    std::vector<double> v = ordinary(x, y, 4);
    if (x == 20) {
      if (y == 20) v[0] = 300.0;
    } else if ((3 * x + 5 * y) % 11 == 0) {
      v[0] = 300.0;
    }
    return v;
  });
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) s.depth.mean(x, y, 0) = x == 20 ? 2.0f : 10.0f;
  const GuardedInput g = guardOutliers(wholeOnly(s));
  ASSERT_LT(g.input.whole.color.mean(20, 20, 0), 10.0f);  // the sparkle was clamped
  for (int y = 0; y < 40; ++y) EXPECT_LT(g.input.whole.color.mean(20, y, 0), 1.5f + 2.0f) << y;
}

TEST(OutlierGuard, TheWholeIsTheMergeOfTheGuardedHalves) {
  // Half 0 holds a firefly at (7, 7), half 1 does not; both have two samples per pixel.
  const SubBuffer h0 = fromSamples(20, 20, [](int x, int y) {
    if (x == 7 && y == 7) return std::vector<double>{1.0, 5e4};
    return std::vector<double>{ordinary(x, y, 5)[0], ordinary(x, y, 5)[1]};
  });
  const SubBuffer h1 = fromSamples(20, 20, [](int x, int y) {
    return std::vector<double>{ordinary(x, y, 6)[0], ordinary(x, y, 6)[1]};
  });
  DenoiseInput in;
  in.whole = merge({&h0, &h1});
  in.halves = std::array<SubBuffer, 2>{h0, h1};
  const GuardedInput g = guardOutliers(in);
  ASSERT_GT(g.clampedValues, 0u);
  const SubBuffer expected = merge({&(*g.input.halves)[0], &(*g.input.halves)[1]});
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(g.input.whole.color.mean(7, 7, c), expected.color.mean(7, 7, c), 1e-5);
    EXPECT_NEAR(g.input.whole.color.varianceOfMean(7, 7, c), expected.color.varianceOfMean(7, 7, c),
                1e-5);
  }
  EXPECT_LT(g.input.whole.color.mean(7, 7, 0), 10.0f);
  // The other half is judged on its own neighbourhood: untouched.
  EXPECT_EQ((*g.input.halves)[1].color.mean(7, 7, 0), h1.color.mean(7, 7, 0));
}

// The ceiling's second term, highFactor (4) × Q, with Q the value exceeded by only a twelfth of
// the neighbours (rank (2r + 1)² − 1) / 12 from the top): around a firefly whose own samples
// do not confirm it (one sample of 4x among four zeros, mean x), every neighbour reads 1 but
// `bright` of them read 10. With rank + 1 bright neighbours Q is 10 and the ceiling 40, with
// rank of them Q is 1 and the ceiling 4; the firefly of 39 is clamped only in the second case,
// one of 41 in both. At every radius the guard takes (each keeps its own length of list).
TEST(OutlierGuard, TheCeilingFollowsTheNeighbourhoodsTwelfthLargestAtEveryRadius) {
  for (int radius = 1; radius <= 4; ++radius) {
    const int rank = ((2 * radius + 1) * (2 * radius + 1) - 1) / 12;
    for (int bright : {rank, rank + 1})
      for (double firefly : {39.0, 41.0}) {
        const int c = 10;
        const SubBuffer s = fromSamples(21, 21, [&](int x, int y) {
          if (x == c && y == c) return std::vector<double>{4 * firefly, 0, 0, 0};
          // The first `bright` neighbours in the window's top row.
          if (y == c - radius && x - (c - radius) < bright && x >= c - radius)
            return std::vector<double>{10, 10, 10, 10};
          return std::vector<double>{1, 1, 1, 1};
        });
        OutlierGuardOptions options;
        options.radius = radius;
        const float out = guardOutliers(wholeOnly(s), options).input.whole.color.mean(c, c, 0);
        const bool clamped = firefly > (bright > rank ? 40.0 : 4.0);
        SCOPED_TRACE("radius " + std::to_string(radius) + ", bright " + std::to_string(bright) +
                     ", firefly " + std::to_string(firefly));
        if (clamped)
          EXPECT_LT(out, 4.0f);
        else
          EXPECT_EQ(out, float(firefly));
      }
  }
}

TEST(OutlierGuard, GuardZeroIsOff) {
  const SubBuffer s = fromSamples(24, 24, [](int x, int y) {
    if (x == 12 && y == 12) return std::vector<double>{1, 1, 1, 1e6};
    return ordinary(x, y, 2);
  });
  OutlierGuardOptions off;
  off.ceilingSigmas = 0;
  EXPECT_EQ(guardOutliers(wholeOnly(s), off).input.whole.color.mean(12, 12, 0),
            s.color.mean(12, 12, 0));
}

}  // namespace
}  // namespace chorus
