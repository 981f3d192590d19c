#include "denoise/base/outlier_guard.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "denoise/util/parallel_rows.h"
#include "denoise/util/simd_clones.h"

namespace chorus {
namespace {

constexpr int kMaxRadius = 4;
constexpr int kMaxNeighbours = (2 * kMaxRadius + 1) * (2 * kMaxRadius + 1) - 1;
// Fewer finite neighbours than this (tiny images, NaN regions) say too little: nothing clamped.
constexpr int kMinNeighbours = 4;
// MAD × this estimates the standard deviation of a normal distribution.
constexpr double kMadToSigma = 1.4826;
constexpr float kMaxFloat = std::numeric_limits<float>::max();
// A few units in the last place of a float, relative.
constexpr double kFloatResolution = 1e-6;

// The sample count of pixel i, or 0 ("unknown") when the buffer has none recorded.
float countAt(const SubBuffer& buffer, size_t i) {
  return buffer.sampleCount.sameSize(buffer.color.mean) ? buffer.sampleCount.data()[i] : 0.0f;
}

// Whether a pixel's samples support an excess over the neighbourhood level: the excess is more
// than `sigmas` standard errors of the mean. Fewer than 2 samples give no variance (0 by
// convention), so nothing is confirmed; an unknown count (0) trusts a positive variance.
// A variance at FLT_MAX is saturated (the film clamps there: the square of a radiance above
// ~1.8e19), a lower bound that confirms nothing.
bool samplesConfirm(double excess, float variance, float count, double sigmas) {
  const bool measured = count == 0.0f ? variance > 0.0f : count >= 2.0f;
  return measured && variance >= 0.0f && variance < kMaxFloat &&
         excess > sigmas * std::sqrt(double(variance));
}

// The pixel's mean with its largest sample taken out, assuming that sample is the one outlier
// among n and the other n − 1 spread like the neighbours' samples (per-sample variance
// n σ_N²): from M2 = M2' + (V − m')² (n − 1)/n with M2' = (n − 2) n σ_N²,
//   m' = m − √(max(0, v − σ_N² (n − 2)/(n − 1))),  v the variance of the mean.
// (One sample V among zeros: v = (V/n)², m' = 0.) A pixel with fewer than 2 samples has only
// the outlier: the neighbourhood level stands in for it.
// The subtraction is only meaningful while float's resolution of the mean (and of its
// standard error) is finer than the neighbours' noise; beyond that the level stands in too.
double withoutLargestSample(double mean, float variance, float count, double level, double noise) {
  const double n = count;
  if (!(variance >= 0.0f && variance < kMaxFloat) || (n > 0.0 && n < 2.0)) return level;
  if (std::abs(mean) * kFloatResolution > noise) return level;
  if (n == 0.0) return mean - std::sqrt(double(variance));  // count unknown
  const double rest = n > 2.0 ? noise * noise * (n - 2.0) / (n - 1.0) : 0.0;
  return mean - std::sqrt(std::max(0.0, double(variance) - rest));
}

struct PixelStats {
  double mean;
  float variance;  // of the mean
  float count;     // 0: unknown
};

// Colour channel c of pixel i of two independent buffers pooled (Chan et al.'s update, as in
// merge()); equal weights when they record no sample counts, the variance then at least the
// two-buffer estimate ¼ (m1 − m2)².
PixelStats mergedAt(const SubBuffer& a, const SubBuffer& b, size_t i, int c) {
  const double n0 = std::max(0.0f, countAt(a, i)), n1 = std::max(0.0f, countAt(b, i));
  const double n = n0 + n1;
  const size_t e = i * 3 + size_t(c);
  const double m0 = a.color.mean.data()[e], m1 = b.color.mean.data()[e];
  const double v0 = a.color.varianceOfMean.data()[e], v1 = b.color.varianceOfMean.data()[e];
  if (!(n > 0)) {
    const double mean = 0.5 * (m0 + m1);
    const double variance = std::max(0.25 * (v0 + v1), 0.25 * (m0 - m1) * (m0 - m1));
    return {mean, float(std::min(variance, double(kMaxFloat))), 0.0f};
  }
  const double mean = (n0 * m0 + n1 * m1) / n;
  const double m2 = n0 * ((n0 > 1 ? v0 * (n0 - 1) : 0.0) + (m0 - mean) * (m0 - mean)) +
                    n1 * ((n1 > 1 ? v1 * (n1 - 1) : 0.0) + (m1 - mean) * (m1 - mean));
  const double variance = n >= 2 ? m2 / (n * (n - 1)) : 0.0;
  return {mean, float(std::min(variance, double(kMaxFloat))), float(n)};
}

// How much a pixel at depth b shares the surface of an outlier at depth a: a Gaussian in their
// relative difference (σ = kSpreadDepthSigma of the larger). A heavy tail belongs to what the
// outlier's pixel sees; spread across a depth edge (onto the black background behind a lamp)
// its energy became a glow where the reference is 0.
constexpr double kSpreadDepthSigma = 0.1;
double sameSurface(double a, double b) {
  if (!std::isfinite(a) || !std::isfinite(b)) return a == b ? 1.0 : 0.0;
  const double scale = kSpreadDepthSigma * std::max(std::abs(a), std::abs(b));
  if (scale == 0.0) return 1.0;
  const double d = (a - b) / scale;
  return std::exp(-0.5 * d * d);
}

// How much a pixel of albedo b shares the material of an outlier of albedo a: a Gaussian in
// their largest channel difference relative to the brighter (σ kSpreadAlbedoSigma). Depth
// alone took a thin light set into a wall (black albedo, the wall's depth) for the wall: the
// light's unconfirmed samples were spread over the wall as a haze.
constexpr double kSpreadAlbedoSigma = 0.5;
double sameMaterial(const float* a, const float* b) {
  double d = 0.0;
  for (int c = 0; c < 3; ++c) {
    if (!std::isfinite(a[c]) || !std::isfinite(b[c])) return 1.0;
    const double scale = std::max(std::abs(double(a[c])), std::abs(double(b[c])));
    if (scale > 0.0) d = std::max(d, std::abs(double(a[c]) - b[c]) / scale);
  }
  d /= kSpreadAlbedoSigma;
  return std::exp(-0.5 * d * d);
}

// How much a pixel of normal b faces the way an outlier of normal a does: a Gaussian in the
// length of their difference (σ kSpreadNormalSigma). A highlight of a small light on a curved
// mirror belongs to the few pixels whose normal reflects the light; depth alone spread it over
// the whole sphere as a glow.
constexpr double kSpreadNormalSigma = 0.1;
double sameOrientation(const float* a, const float* b) {
  double d2 = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double d = double(a[c]) - b[c];
    d2 += d * d;
  }
  if (!std::isfinite(d2)) return 1.0;
  return std::exp(-0.5 * d2 / (kSpreadNormalSigma * kSpreadNormalSigma));
}

// How much the pixels q around a pixel p see what p sees: `weight` times the three similarities
// above, in that order, over the features the part holds (one it does not hold counts as the
// same). p's own features are looked up once.
class WhatItSees {
 public:
  WhatItSees(const SubBuffer& part, int px, int py)
      : depth_(part.depth.mean),
        albedo_(part.albedo.mean),
        normal_(part.normal.mean),
        here_(depth_.sameSize(part.color.mean) ? depth_.pixel(px, py) : nullptr),
        material_(albedo_.sameSize(part.color.mean) ? albedo_.pixel(px, py) : nullptr),
        facing_(normal_.sameSize(part.color.mean) ? normal_.pixel(px, py) : nullptr) {}
  double shared(int qx, int qy, double weight = 1.0) const {
    return weight * (here_ ? sameSurface(*here_, depth_(qx, qy, 0)) : 1.0) *
           (material_ ? sameMaterial(material_, albedo_.pixel(qx, qy)) : 1.0) *
           (facing_ ? sameOrientation(facing_, normal_.pixel(qx, qy)) : 1.0);
  }

 private:
  const Image &depth_, &albedo_, &normal_;
  const float *here_, *material_, *facing_;
};

// The value exceeded by exactly `rank` of values[0 … count) (0: the largest), for a small rank:
// the running top rank + 1 in insertion order.
float largest(const float* values, int count, int rank) {
  std::array<float, kMaxNeighbours> top;
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    const float v = values[i];
    if (kept == rank + 1 && !(v > top[size_t(rank)])) continue;
    int j = kept < rank + 1 ? kept++ : rank;
    for (; j > 0 && top[size_t(j - 1)] < v; --j) top[size_t(j)] = top[size_t(j - 1)];
    top[size_t(j)] = v;
  }
  return top[size_t(rank)];
}

// Per pixel x of a row, over its (2 r + 1)² − 1 neighbours in `rows` (2 r + 1 rows of one
// channel, `padded` apart, with r NaN columns on the left and NaN up to a whole number of
// kRankLanes and r more on the right): how many are finite, how many are below the pixel, and
// the `tops` largest in descending order (largest[k · stride + x]; exact only where every
// neighbour is finite, which is where it is read).
constexpr int kRankLanes = 8;
struct NeighbourRanks {
  NeighbourRanks(int width, int radius, int tops)
      : stride(size_t((width + kRankLanes - 1) / kRankLanes) * kRankLanes),
        padded(stride + size_t(2 * radius)),
        tops(tops),
        rows(size_t(2 * radius + 1) * padded, std::numeric_limits<float>::quiet_NaN()),
        count(stride),
        below(stride),
        largest(stride * size_t(tops)) {}
  size_t stride, padded;
  int tops;
  std::vector<float> rows;
  std::vector<int> count, below;
  std::vector<float> largest;
};

// kRankLanes pixels at a time in GCC vector types (each clone picks its instructions), their
// running counts and lists in registers (written as plain loops, the lists became masked stores).
using FloatLanes = float __attribute__((vector_size(kRankLanes * sizeof(float))));
using IntLanes = int __attribute__((vector_size(kRankLanes * sizeof(int))));

template <int kTops>
CHORUS_SIMD_CLONES_EXACT void rankNeighboursOf(const float* rows, size_t padded, int r,
                                               size_t stride, int* count, int* below,
                                               float* largest) {
  for (size_t x0 = 0; x0 < stride; x0 += kRankLanes) {
    FloatLanes centre;
    std::memcpy(&centre, rows + size_t(r) * padded + size_t(r) + x0, sizeof centre);
    IntLanes finite = {}, lower = {};
    FloatLanes top[kTops];
    for (int k = 0; k < kTops; ++k) top[k] = FloatLanes{} - std::numeric_limits<float>::infinity();
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        if (dx == 0 && dy == 0) continue;
        FloatLanes v;
        std::memcpy(&v, rows + size_t(dy + r) * padded + size_t(r + dx) + x0, sizeof v);
        finite -= (v - v == 0.0f);  // comparisons give −1 where true
        lower -= (v < centre);
        for (int k = 0; k < kTops; ++k) {  // insert v into the descending list
          const IntLanes greater = top[k] > v;
          const FloatLanes t = top[k];
          top[k] = greater ? t : v;
          v = greater ? v : t;
        }
      }
    std::memcpy(count + x0, &finite, sizeof finite);
    std::memcpy(below + x0, &lower, sizeof lower);
    for (int k = 0; k < kTops; ++k)
      std::memcpy(largest + size_t(k) * stride + x0, &top[k], sizeof top[k]);
  }
}

void rankNeighbours(int r, NeighbourRanks& ranks) {
  const float* rows = ranks.rows.data();
  int* count = ranks.count.data();
  int* below = ranks.below.data();
  float* largest = ranks.largest.data();
  switch (ranks.tops) {
    case 1:
      return rankNeighboursOf<1>(rows, ranks.padded, r, ranks.stride, count, below, largest);
    case 3:
      return rankNeighboursOf<3>(rows, ranks.padded, r, ranks.stride, count, below, largest);
    case 5:
      return rankNeighboursOf<5>(rows, ranks.padded, r, ranks.stride, count, below, largest);
    case 7:
      return rankNeighboursOf<7>(rows, ranks.padded, r, ranks.stride, count, below, largest);
    default:
      throw std::logic_error("rankNeighbours: unexpected rank");
  }
}

// tailFillsTheWindow's peers: at least 1 / kPeerFraction of the outlier's excess each, spread
// over at least kPeerAreaSpread px² (the smaller variance of their positions).
constexpr double kPeerFraction = 4.0;
constexpr double kPeerAreaSpread = 2.0;

class PartGuard {
 public:
  PartGuard(const SubBuffer& part, const SubBuffer* other, const OutlierGuardOptions& options)
      : part_(part), other_(other), o_(options) {}

  // Clamps the outliers of the part's colour into `out` (a copy of it); marks the pixels that
  // changed. Returns how many values changed.
  size_t run(MeanVariance& out, std::vector<uint8_t>& changed) const {
    const int h = part_.height();
    std::vector<size_t> rowCounts(size_t(h), 0);
    std::vector<std::vector<Excess>> rowExcess(static_cast<size_t>(h));
    parallelRows(0, h, [&](int y) {
      rowCounts[size_t(y)] = guardRow(y, out, changed, rowExcess[size_t(y)]);
    });
    std::vector<Excess> excesses;
    for (const std::vector<Excess>& row : rowExcess)
      excesses.insert(excesses.end(), row.begin(), row.end());
    spreadAll(excesses, out, changed);
    return std::accumulate(rowCounts.begin(), rowCounts.end(), size_t(0));
  }

 private:
  // What an outlier had above its replacement, to be spread over its neighbourhood.
  struct Excess {
    int x, y, c;
    double amount;
    int radius;  // of the window it is spread over (spreadRadiusFor)
  };

  // spreadRadius, or wider where a blob of that radius would stand far above the outlier's
  // neighbourhood: the radius at which its peak, about 2 amount / (π r²) (a Gaussian of
  // σ = r / 2), is spreadPeak × (L + σ_N), up to kMaxGuardSpread. A caustic path found once
  // among 64 samples of a pixel whose neighbours read 0.004 (an excess of ~50) left a blob of
  // ~0.8 over the dark pixels around it at radius 6. Where L is 0 the neighbourhood's light
  // comes in sparse samples whose level the median does not measure: the radius stays.
  int spreadRadiusFor(double amount, double level, double noise) const {
    const int r = o_.spreadRadius;
    if (!(o_.spreadPeak > 0.0f) || !(level > 0.0)) return r;
    const double wanted =
        std::sqrt(2.0 * amount / (std::numbers::pi * o_.spreadPeak * (level + noise)));
    return wanted > r ? int(std::ceil(std::min(wanted, double(kMaxGuardSpread)))) : r;
  }

  // Whether the outlier at (x, y) is one sample of a tail that is spread over an area of its
  // surface around it, though its 5 × 5 neighbourhood may hold no other: over the spread window
  // (radius spreadRadius), the neighbours whose excess over the level is at least
  // 1 / kPeerFraction of the outlier's, weighted by how much they see what it sees, must hold
  // together at least as much excess as it does, and fill an area rather than a line: the
  // smaller eigenvalue of the covariance of their positions (weighted by excess, the outlier's
  // own included) is at least kPeerAreaSpread px². Spreading such an excess keeps the surface's
  // light; dropping it darkened whole walls lit by rare paths (a corridor at 4 spp lost 7 % of
  // its light and NFOR doubled its error: docs/outliers.md). A bright line (a light's edge, a
  // glint) is not such a tail: its excess spread over the window became a halo beside it.
  bool tailFillsTheWindow(int x, int y, int c, double level, double excess) const {
    const Image& mean = part_.color.mean;
    const int w = mean.width(), h = mean.height(), r = o_.spreadRadius;
    const WhatItSees sees(part_, x, y);
    // Excess-weighted sums over the peers and the outlier at (0, 0): their weight, the peers'
    // share of it being sw − excess, and the first and second moments of their positions.
    double sw = excess, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    for (int qy = std::max(0, y - r); qy <= std::min(h - 1, y + r); ++qy)
      for (int qx = std::max(0, x - r); qx <= std::min(w - 1, x + r); ++qx) {
        const double d = double(mean(qx, qy, c)) - level;
        if ((qx == x && qy == y) || !(std::isfinite(d) && d * kPeerFraction >= excess)) continue;
        const double m = d * sees.shared(qx, qy);
        const double dx = qx - x, dy = qy - y;
        sw += m;
        sx += m * dx;
        sy += m * dy;
        sxx += m * dx * dx;
        syy += m * dy * dy;
        sxy += m * dx * dy;
      }
    if (!(sw - excess >= excess)) return false;
    const double mx = sx / sw, my = sy / sw;
    const double a = sxx / sw - mx * mx, b = sxy / sw - mx * my, d = syy / sw - my * my;
    const double smaller = 0.5 * (a + d) - std::sqrt(0.25 * (a - d) * (a - d) + b * b);
    return smaller >= kPeerAreaSpread;
  }

  // The Gaussians g of spread by radius, g(dx, dy) at |dy| (r + 1) + |dx|: computed once per
  // radius instead of twice per pixel of every window.
  struct SpreadKernels {
    std::array<std::vector<double>, kMaxGuardSpread + 1> byRadius;
    const std::vector<double>& of(int r) {
      std::vector<double>& g = byRadius[size_t(r)];
      if (g.empty()) {
        const double falloff = 2.0 / (double(r) * double(r));  // 1 / (2 σ²), σ = r / 2
        g.resize(size_t(r + 1) * size_t(r + 1));
        for (int dy = 0; dy <= r; ++dy)
          for (int dx = 0; dx <= r; ++dx)
            g[size_t(dy * (r + 1) + dx)] = std::exp(-double(dx * dx + dy * dy) * falloff);
      }
      return g;
    }
  };

  // Adds amount × g(q) s(q) / Σ g to every pixel q of the (2 e.radius + 1)² window inside
  // the image, the outlier's own included, with the Gaussian g(q) = exp(−|q − p|² / (2 (r/2)²))
  // and s(q) = sameSurface: on one surface the window keeps the outlier's energy, without the
  // edges a box would draw. The share that falls on other surfaces is dropped, not given to the
  // outlier's surface: on a thin one (a lamp's arm, a few pixels wide) that concentrated an
  // excess of the whole window onto a handful of pixels (0.96 where the reference is 0.004).
  // `excesses` in raster order. Rows in parallel, each adding its excesses in that order, so
  // that every pixel's sum is the same whatever the thread count.
  void spreadAll(const std::vector<Excess>& excesses, MeanVariance& out,
                 std::vector<uint8_t>& changed) const {
    if (excesses.empty()) return;
    const int w = part_.width(), h = part_.height();
    SpreadKernels kernels;
    for (const Excess& e : excesses) kernels.of(e.radius);
    // Σ g over each window's part inside the image.
    std::vector<double> totals(excesses.size());
    parallelChunks(excesses.size(), [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        const Excess& e = excesses[i];
        const std::vector<double>& g = kernels.byRadius[size_t(e.radius)];
        double total = 0;
        for (int y = std::max(0, e.y - e.radius); y <= std::min(h - 1, e.y + e.radius); ++y)
          for (int x = std::max(0, e.x - e.radius); x <= std::min(w - 1, e.x + e.radius); ++x)
            total += g[size_t(std::abs(y - e.y) * (e.radius + 1) + std::abs(x - e.x))];
        totals[i] = total;
      }
    });
    parallelRows(0, h, [&](int y) {
      // The excesses whose windows can reach row y: e.y within kMaxGuardSpread of it.
      auto first = std::lower_bound(excesses.begin(), excesses.end(), y - kMaxGuardSpread,
                                    [](const Excess& e, int row) { return e.y < row; });
      for (auto it = first; it != excesses.end() && it->y <= y + kMaxGuardSpread; ++it) {
        const Excess& e = *it;
        const int r = e.radius, dy = std::abs(y - e.y);
        if (dy > r) continue;
        const std::vector<double>& g = kernels.byRadius[size_t(r)];
        const double total = totals[size_t(it - excesses.begin())];
        const WhatItSees sees(part_, e.x, e.y);
        for (int x = std::max(0, e.x - r); x <= std::min(w - 1, e.x + r); ++x) {
          const double share =
              sees.shared(x, y, g[size_t(dy * (r + 1) + std::abs(x - e.x))]) / total;
          float& m = out.mean(x, y, e.c);
          m = float(std::min(double(m) + e.amount * share, double(kMaxFloat)));
          changed[size_t(y) * size_t(w) + size_t(x)] = 1;
        }
      }
    });
  }

  // Per channel, 1 at the pixels of row y that can be outliers: a finite value with at least
  // kMinNeighbours finite neighbours, at most a twelfth of which reach it, and where every
  // neighbour is finite, above highFactor · Q (the first two tests of guardRow, for whole rows
  // at once: most pixels stop here). Neighbours outside the image read as NaN padding, which is
  // neither finite nor below anything.
  std::array<std::vector<uint8_t>, 3> candidatesOfRow(int y) const {
    const Image& mean = part_.color.mean;
    const int w = mean.width(), h = mean.height(), r = o_.radius;
    const int full = (2 * r + 1) * (2 * r + 1) - 1, highRank = full / 12;
    NeighbourRanks ranks(w, r, highRank + 1);
    std::array<std::vector<uint8_t>, 3> out;
    for (int c = 0; c < 3; ++c) {
      for (int dy = -r; dy <= r; ++dy) {
        if (y + dy < 0 || y + dy >= h) continue;
        float* row = ranks.rows.data() + size_t(dy + r) * ranks.padded + size_t(r);
        for (int x = 0; x < w; ++x) row[x] = mean(x, y + dy, c);
      }
      rankNeighbours(r, ranks);
      const float* centre = ranks.rows.data() + size_t(r) * ranks.padded + size_t(r);
      const float* high = ranks.largest.data() + size_t(highRank) * ranks.stride;
      out[size_t(c)].resize(size_t(w));
      for (int x = 0; x < w; ++x) {
        const int n = ranks.count[size_t(x)];
        bool candidate =
            std::isfinite(centre[x]) && n >= kMinNeighbours && n - ranks.below[size_t(x)] <= n / 12;
        // Q is exact where every neighbour is finite (guardRow's test, in the same precision).
        if (candidate && n == full && high[x] > 0.0f)
          candidate = centre[x] > double(o_.highFactor) * double(high[x]);
        out[size_t(c)][size_t(x)] = candidate;
      }
    }
    return out;
  }

  size_t guardRow(int y, MeanVariance& out, std::vector<uint8_t>& changed,
                  std::vector<Excess>& excesses) const {
    const Image& mean = part_.color.mean;
    const Image& variance = part_.color.varianceOfMean;
    const int w = mean.width(), h = mean.height(), r = o_.radius;
    std::array<float, kMaxNeighbours> values, spreads;
    size_t clamped = 0;
    const std::array<std::vector<uint8_t>, 3> candidates = candidatesOfRow(y);
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        if (!candidates[size_t(c)][size_t(x)]) continue;
        const float value = mean(x, y, c);
        int count = 0;
        for (int qy = std::max(0, y - r); qy <= std::min(h - 1, y + r); ++qy)
          for (int qx = std::max(0, x - r); qx <= std::min(w - 1, x + r); ++qx) {
            if (qx == x && qy == y) continue;
            const float m = mean(qx, qy, c);
            if (!std::isfinite(m)) continue;
            values[size_t(count++)] = m;
          }
        // Q = the value exceeded by `highRank` neighbours (value > Q: candidatesOfRow).
        const int highRank = count / 12;
        // The ceiling is at least highFactor · Q: most candidates stop here, before any sorting.
        const double high = largest(values.data(), count, highRank);
        if (high > 0 && !(value > o_.highFactor * high)) continue;
        float* first = values.data();
        // (The same order of the values as always: the sums below depend on it.)
        std::nth_element(first, first + highRank, first + count, std::greater<float>());
        std::nth_element(first, first + count / 2, first + count);
        const double level = first[count / 2];

        int spreadCount = 0;
        for (int qy = std::max(0, y - r); qy <= std::min(h - 1, y + r); ++qy)
          for (int qx = std::max(0, x - r); qx <= std::min(w - 1, x + r); ++qx) {
            if (qx == x && qy == y) continue;
            const float v = variance(qx, qy, c);
            if (std::isfinite(v) && v >= 0.0f && std::isfinite(mean(qx, qy, c)))
              spreads[size_t(spreadCount++)] = std::sqrt(v);
          }
        double noise = 0;
        if (spreadCount > 0) {
          std::nth_element(spreads.data(), spreads.data() + spreadCount / 2,
                           spreads.data() + spreadCount);
          noise = spreads[size_t(spreadCount / 2)];
        }
        for (int i = 0; i < count; ++i) spreads[size_t(i)] = float(std::abs(first[i] - level));
        std::nth_element(spreads.data(), spreads.data() + count / 2, spreads.data() + count);
        noise = std::max(noise, kMadToSigma * spreads[size_t(count / 2)]);

        const double ceiling =
            std::max(level + o_.ceilingSigmas * noise, high > 0 ? o_.highFactor * high : high);
        if (!(value > ceiling)) continue;
        const size_t pixel = size_t(y) * size_t(w) + size_t(x);
        // The evidence: the pixel's samples in this part, or in both halves when the other
        // half has the pixel (a second, independent firefly in the other half does not make
        // two halves that agree: their pooled samples still do not confirm the excess).
        const bool pool = other_ && std::isfinite(other_->color.mean(x, y, c));
        const PixelStats evidence =
            pool ? mergedAt(part_, *other_, pixel, c)
                 : PixelStats{value, variance(x, y, c), countAt(part_, pixel)};
        if (samplesConfirm(evidence.mean - level, evidence.variance, evidence.count,
                           o_.confirmSigmas))
          continue;
        const double replacement =
            withoutLargestSample(value, variance(x, y, c), countAt(part_, pixel), level, noise);
        const double clampedValue = std::clamp(replacement, std::min(0.0, level), ceiling);
        out.mean(x, y, c) = float(clampedValue);
        // Peers: neighbours that deviate from L as much make the RMS deviation of the
        // neighbourhood comparable to this excess. The outlier is then one of many samples of
        // a heavy-tailed distribution present here (a caustic), whose energy is part of the
        // image: it is spread over the window rather than dropped.
        double squares = 0;
        for (int i = 0; i < count; ++i) squares += (first[i] - level) * (first[i] - level);
        const double surplus = value - clampedValue;
        if (value - level <= o_.peerSigmas * std::sqrt(squares / count) ||
            tailFillsTheWindow(x, y, c, level, value - level))
          excesses.push_back({x, y, c, surplus, spreadRadiusFor(surplus, level, noise)});
        const double excess = clampedValue - level;
        const double cap = std::max(noise * noise, excess * excess);
        const float v = variance(x, y, c);
        out.varianceOfMean(x, y, c) =
            std::isfinite(v) ? float(std::min(double(v), cap)) : float(std::min(cap, 3.0e38));
        changed[pixel] = 1;
        ++clamped;
      }
    return clamped;
  }

  const SubBuffer& part_;
  const SubBuffer* other_;
  const OutlierGuardOptions& o_;
};

// The whole's colour at pixel i re-merged from the two halves.
void remergeColor(const std::array<SubBuffer, 2>& halves, size_t i, SubBuffer& whole) {
  for (int c = 0; c < 3; ++c) {
    const PixelStats merged = mergedAt(halves[0], halves[1], i, c);
    whole.color.mean.data()[i * 3 + size_t(c)] = float(merged.mean);
    whole.color.varianceOfMean.data()[i * 3 + size_t(c)] = merged.variance;
  }
}

}  // namespace

GuardedInput guardOutliers(DenoiseInput input, const OutlierGuardOptions& options) {
  if (options.radius < 1 || options.radius > kMaxRadius)
    throw std::invalid_argument("guardOutliers: radius must be in [1, 4]");
  GuardedInput result;
  if (options.ceilingSigmas == 0.0f) {
    result.input = std::move(input);
    return result;
  }
  // The guard reads the input as given and writes into its own copy of the colour.
  std::vector<uint8_t> changed(input.whole.color.mean.pixelCount(), 0);
  if (!input.halves) {
    MeanVariance color = input.whole.color;
    result.clampedValues = PartGuard(input.whole, nullptr, options).run(color, changed);
    input.whole.color = std::move(color);
    result.input = std::move(input);
    return result;
  }
  auto& halves = *input.halves;
  std::array<MeanVariance, 2> colors = {halves[0].color, halves[1].color};
  for (int k = 0; k < 2; ++k)
    result.clampedValues += PartGuard(halves[size_t(k)], &halves[size_t(1 - k)], options)
                                .run(colors[size_t(k)], changed);
  for (int k = 0; k < 2; ++k) halves[size_t(k)].color = std::move(colors[size_t(k)]);
  if (result.clampedValues > 0)
    for (size_t i = 0; i < changed.size(); ++i)
      if (changed[i]) remergeColor(halves, i, input.whole);
  result.input = std::move(input);
  return result;
}

}  // namespace chorus
