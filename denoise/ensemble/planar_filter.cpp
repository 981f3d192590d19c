#include "denoise/ensemble/planar_filter.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "denoise/util/fast_exp.h"
#include "denoise/util/simd_clones.h"

namespace chorus {
namespace {

constexpr float kVarianceFloor = 1e-6f;

// Sixteen floats: one AVX-512 register, two AVX2 or four SSE registers (each clone picks).
constexpr int kLanes = 16;
typedef float Lanes __attribute__((vector_size(kLanes * sizeof(float))));
// Tile width in columns (a multiple of kLanes): wide, so that few kernel values are computed
// twice at tile edges; small enough that the tile's buffers stay in L2.
constexpr int kBlock = 256;

// The guide values of a run of kLanes pixel pairs: plane m of p at p[m], of q at q[m]
// (m = 0…2 normal, 3…5 albedo, 6…8 colour, 9…11 variance).
struct GuideLanes {
  const float* p[12];
  const float* q[12];
};

// The kernel's arithmetic runs on eight lanes at a time: AVX2's width (with sixteen, GCC split
// the exponential's selects into SSE pieces and spilled to the stack).
constexpr int kKernelWidth = 8;
typedef float KernelLanes __attribute__((vector_size(kKernelWidth * sizeof(float))));
typedef int32_t KernelInts __attribute__((vector_size(kKernelWidth * sizeof(int32_t))));

// Any of these vector types from and to floats at any alignment, through references (a vector
// returned by value would change the ABI of the baseline clone).
template <typename V>
[[gnu::always_inline]] inline void loadVector(V& v, const float* p) {
  std::memcpy(&v, p, sizeof v);
}
template <typename V>
[[gnu::always_inline]] inline void storeVector(float* p, const V& v) {
  std::memcpy(p, &v, sizeof v);
}

// sum = Σ_{m = m0 … m0+2} (p_m − q_m)², in that order, for the lanes from `at`.
[[gnu::always_inline]] inline void squaredDifferences(const GuideLanes& g, int m0, int at,
                                                      KernelLanes& sum) {
  KernelLanes p, q;
  loadVector(p, g.p[m0] + at);
  loadVector(q, g.q[m0] + at);
  sum = (p - q) * (p - q);
  for (int m = m0 + 1; m < m0 + 3; ++m) {
    loadVector(p, g.p[m] + at);
    loadVector(q, g.q[m] + at);
    sum = sum + (p - q) * (p - q);
  }
}

// Kernel values k[l] = k(p_l, q_l), l < kLanes: fixed-length loops, so that every pair is
// computed by the same vector code whatever its position in a row.
template <bool kColor>
[[gnu::always_inline]] inline void kernelLanes(const GuideLanes& g, float spatial,
                                               const BilateralKernel& kernel, float* k) {
  const float kn = kernel.kNormal, ka = kernel.kAlbedo, kc = kernel.kColor;
  for (int at = 0; at < kLanes; at += kKernelWidth) {
    // Plane by plane straight from the guides (an array of the runs' vectors went through the
    // stack); the sums in the scalar definition's order.
    KernelLanes normal, albedo;
    squaredDifferences(g, 0, at, normal);
    squaredDifferences(g, 3, at, albedo);
    KernelLanes d = spatial + kn * normal + ka * albedo;
    if (kColor) {
      // Σ_c dz_c²/s_c with one division: (a·s1·s2 + b·s0·s2 + c·s0·s1) / (s0·s1·s2); the
      // guide's bounds (|z| ≤ 1e6, V ≤ 1e12) keep every product finite.
      KernelLanes dz[3], sc[3], p, q;
      for (int c = 0; c < 3; ++c) {
        loadVector(p, g.p[6 + c] + at);
        loadVector(q, g.q[6 + c] + at);
        dz[c] = p - q;
        loadVector(p, g.p[9 + c] + at);
        loadVector(q, g.q[9 + c] + at);
        sc[c] = p + q + kVarianceFloor;
      }
      d = d + kc * ((dz[0] * dz[0] * (sc[1] * sc[2]) + dz[1] * dz[1] * (sc[0] * sc[2]) +
                     dz[2] * dz[2] * (sc[0] * sc[1])) /
                    (sc[0] * sc[1] * sc[2]));
    }
    KernelLanes kv;
    fastExpNegatedVector<KernelLanes, KernelInts>(d, kv);
    std::memcpy(k + at, &kv, sizeof kv);
  }
}

// Kernel values k[i] for the pixels x = x0 + i (i < count) of row y and offset (dx, dy). Writes
// whole runs of kLanes: k must have room for count rounded up to kLanes (the values past count
// are unspecified). A last partial run is read in place where the guide planes extend far
// enough, else from a zero-padded copy.
template <bool kColor>
[[gnu::always_inline]] inline void kernelRowOf(const PlanarGuides& g, const BilateralKernel& kernel,
                                               int y, int dx, int dy, int x0, int count, float* k) {
  const size_t pixels = size_t(g.width) * size_t(g.height);
  const size_t rowP = size_t(y) * size_t(g.width) + size_t(x0);
  const size_t rowQ = size_t(y + dy) * size_t(g.width) + size_t(x0 + dx);
  const float spatial = kernel.kSpatial * float(dx * dx + dy * dy);
  const std::vector<float>* planes[4] = {&g.normal, &g.albedo, &g.color, &g.variance};
  const int planeCount = kColor ? 12 : 6;
  GuideLanes run;
  for (int m = 0; m < planeCount; ++m) {
    const float* base = planes[m / 3]->data() + size_t(m % 3) * pixels;
    run.p[m] = base + rowP;
    run.q[m] = base + rowQ;
  }
  int i = 0;
  for (; i + kLanes <= count; i += kLanes) {
    kernelLanes<kColor>(run, spatial, kernel, k + i);
    for (int m = 0; m < planeCount; ++m) run.p[m] += kLanes, run.q[m] += kLanes;
  }
  if (i == count) return;
  if (std::max(rowP, rowQ) + size_t(i + kLanes) <= pixels) {
    kernelLanes<kColor>(run, spatial, kernel, k + i);
    return;
  }
  float padded[2][12][kLanes] = {};
  for (int m = 0; m < planeCount; ++m) {
    std::copy(run.p[m], run.p[m] + (count - i), padded[0][m]);
    std::copy(run.q[m], run.q[m] + (count - i), padded[1][m]);
    run.p[m] = padded[0][m];
    run.q[m] = padded[1][m];
  }
  kernelLanes<kColor>(run, spatial, kernel, k + i);
}

CHORUS_SIMD_CLONES_EXACT void kernelRow(const PlanarGuides& g, const BilateralKernel& kernel, int y,
                                        int dx, int dy, int x0, int count, float* k) {
  if (kernel.kColor > 0)
    kernelRowOf<true>(g, kernel, y, dx, dy, x0, count, k);
  else
    kernelRowOf<false>(g, kernel, y, dx, dy, x0, count, k);
}

// One tile of the output (rows [y0, y1), columns [x0, x0 + width)) and its buffers, all rows
// of `stride` floats starting at column x0 − r:
//   source: plane j, rows y0 − r … y1 + r − 1 (zeros outside the image),
//   kernel: per dx of the current row of offsets dy, a ring of dy + 1 rows: k(s, s + δ) for the
//           last rows s computed (0 where s or s + δ is outside the image),
//   acc:    plane 0 the weight sum Σk, plane 1 + j the weighted sum of plane j; rows y0 … y1 − 1
//           of `width` floats from column x0.
struct Tile {
  int width, stride, r, step;
  const float* source;
  size_t sourcePlane;
  const float* kernel;
  size_t kernelPlane;
  float* acc;
  size_t accPlane;
};

// Where one output row finds its terms for the row of offsets dy: tile row y, and the kernel
// ring slots of the rows s = y (for q = p + δ) and s = y − dy (for q = p − δ).
struct RowTerms {
  int y, dy, dxLo, plusSlot, minusSlot;
};

// Adds the offsets (dx, dy), dx = dxLo … r, to kLanes accumulators of planes j0 … j0 + G − 1
// (and of the weight sum when kSum) at column col. Per offset the terms are added in the order
// of the definition — q = p + δ, then q = p − δ — so the accumulators in registers give the
// same bits as a pass over memory per offset.
template <typename V, int G, bool kSum>
[[gnu::always_inline]] inline void accumulateLanes(const Tile& t, const RowTerms& row, int j0,
                                                   int col) {
  const size_t accAt = size_t(row.y) * size_t(t.width) + size_t(col);
  V sum{}, acc[G];
  if (kSum) loadVector(sum, t.acc + accAt);
#pragma GCC unroll 16
  for (int g = 0; g < G; ++g) loadVector(acc[g], t.acc + size_t(1 + j0 + g) * t.accPlane + accAt);
  const float* source = t.source + size_t(j0) * t.sourcePlane;
  const size_t plusRow = size_t(row.y + row.dy + t.r) * size_t(t.stride);
  const size_t minusRow = size_t(row.y - row.dy + t.r) * size_t(t.stride);
  const float* kPlusRow = t.kernel + size_t(row.plusSlot) * size_t(t.stride) + size_t(col + t.r);
  const float* kMinusRow = t.kernel + size_t(row.minusSlot) * size_t(t.stride) + size_t(col + t.r);
  for (int dx = row.dxLo; dx <= t.r; dx += t.step) {
    // k(p, p + δ) is stored at s = p, k(p − δ, p) at s = p − δ.
    const size_t plane = size_t(dx + t.r) * t.kernelPlane;
    V kPlus, kMinus;
    loadVector(kPlus, kPlusRow + plane);
    loadVector(kMinus, kMinusRow + plane - dx);
    if (kSum) {
      sum += kPlus;
      sum += kMinus;
    }
    const size_t plus = plusRow + size_t(col + dx + t.r), minus = minusRow + size_t(col - dx + t.r);
#pragma GCC unroll 16
    for (int g = 0; g < G; ++g) {
      const float* s = source + size_t(g) * t.sourcePlane;
      V qPlus, qMinus;
      loadVector(qPlus, s + plus);
      loadVector(qMinus, s + minus);
      acc[g] += kPlus * qPlus;
      acc[g] += kMinus * qMinus;
    }
  }
  if (kSum) storeVector(t.acc + accAt, sum);
#pragma GCC unroll 16
  for (int g = 0; g < G; ++g) storeVector(t.acc + size_t(1 + j0 + g) * t.accPlane + accAt, acc[g]);
}

// Adds the row of offsets dy to the accumulators of one output row, planes in groups of up to
// 8 (the weight sum with the first group) so that a group's accumulators stay in registers
// while the offsets are looped.
template <typename V>
[[gnu::always_inline]] inline void accumulateRowOf(const Tile& t, int planes, const RowTerms& row) {
  for (int col = 0; col < t.width; col += int(sizeof(V) / sizeof(float)))
    for (int j = 0; j < planes;) {
      const int left = planes - j;
      const bool first = j == 0;
      if (left >= 8) {
        first ? accumulateLanes<V, 8, true>(t, row, j, col)
              : accumulateLanes<V, 8, false>(t, row, j, col);
        j += 8;
      } else if (left >= 4) {
        first ? accumulateLanes<V, 4, true>(t, row, j, col)
              : accumulateLanes<V, 4, false>(t, row, j, col);
        j += 4;
      } else if (left >= 2) {
        first ? accumulateLanes<V, 2, true>(t, row, j, col)
              : accumulateLanes<V, 2, false>(t, row, j, col);
        j += 2;
      } else {
        first ? accumulateLanes<V, 1, true>(t, row, j, col)
              : accumulateLanes<V, 1, false>(t, row, j, col);
        j += 1;
      }
    }
}

// Sixteen lanes per vector where the CPU has AVX-512 (one register each), else eight: sixteen
// on AVX2 spilled the accumulators (8-15 % slower combination step). The same sums either way.
CHORUS_SIMD_CLONES_EXACT void accumulateRow(const Tile& t, int planes, const RowTerms& row,
                                            bool wide) {
  if (wide)
    accumulateRowOf<Lanes>(t, planes, row);
  else
    accumulateRowOf<KernelLanes>(t, planes, row);
}

}  // namespace

void filterPlaneRows(const PlanarGuides& guides, const BilateralKernel& kernel,
                     std::span<const float* const> in, int inY0, int y0, int y1,
                     std::span<float* const> out) {
  const int w = guides.width, h = guides.height, r = std::max(0, kernel.radius);
  const int step = std::clamp(kernel.step, 1, std::max(1, r));
  const int reach = r / step * step;  // the furthest offset on the grid of steps
  const int planes = int(in.size());
  const int rows = y1 - y0;
  if (planes == 0 || rows <= 0) return;
  const bool wide = kernel.width == BilateralKernel::Width::ForThisCpu
                        ? cpuHasAvx512f()
                        : kernel.width == BilateralKernel::Width::Sixteen;
  // The kernel is symmetric, k(s, s+δ) = k(s+δ, s) bit for bit, so it is evaluated once per
  // pair for the offsets δ of one half-plane and applied in both directions. Every output value
  // receives its terms in one fixed order (centre, then per δ: q = p + δ, q = p − δ; a pair
  // with q outside the image adds k = 0 times a source 0, which changes no bit), so results do
  // not depend on how the image is cut into tiles or rows.
  // Kernel rows are written in whole runs of kLanes (kernelRow): one run of slack.
  const int stride = kBlock + 2 * r + kLanes;
  // Per-thread buffers kept between calls (the solve and the weight filter call this once per
  // band of rows: fresh vectors cost page faults and zero-filling). Every value read below is
  // written first: the source rows and accumulators per tile, the kernel ring per offset.
  thread_local std::vector<float> source, k, acc;
  source.resize(size_t(planes) * size_t(rows + 2 * r) * size_t(stride));
  k.resize(size_t(2 * r + 1) * size_t(r + 1) * size_t(stride));
  acc.resize(size_t(planes + 1) * size_t(rows) * size_t(kBlock));
  Tile tile;
  tile.stride = stride;
  tile.r = r;
  tile.step = step;
  tile.source = source.data();
  tile.sourcePlane = size_t(rows + 2 * r) * size_t(stride);
  tile.kernel = k.data();
  tile.kernelPlane = size_t(r + 1) * size_t(stride);
  tile.acc = acc.data();
  tile.accPlane = size_t(rows) * size_t(kBlock);
  for (int x0 = 0; x0 < w; x0 += kBlock) {
    const int x1 = std::min(w, x0 + kBlock);
    // Whole lane chunks; columns from x1 on are computed on zeros and not written out.
    const int width = (x1 - x0 + kLanes - 1) / kLanes * kLanes;
    tile.width = width;

    // Source planes with a zero border; the centre tap k(p, p) = 1 starts the sums.
    const int cx0 = std::max(0, x0 - r), cx1 = std::min(w, x1 + r);
    for (int j = 0; j < planes; ++j)
      for (int y = y0 - r; y < y1 + r; ++y) {
        float* dst =
            source.data() + size_t(j) * tile.sourcePlane + size_t(y - (y0 - r)) * size_t(stride);
        std::fill(dst, dst + stride, 0.0f);
        if (y < 0 || y >= h) continue;
        const float* src = in[size_t(j)] + size_t(y - inY0) * size_t(w);
        std::copy(src + cx0, src + cx1, dst + (cx0 - (x0 - r)));
      }
    for (int y = 0; y < rows; ++y) {
      std::fill_n(acc.data() + size_t(y) * size_t(width), width, 1.0f);
      for (int j = 0; j < planes; ++j)
        std::copy_n(source.data() + size_t(j) * tile.sourcePlane + size_t(y + r) * size_t(stride) +
                        size_t(r),
                    width, acc.data() + size_t(j + 1) * tile.accPlane + size_t(y) * size_t(width));
    }

    // Per row of offsets dy, kernel rows s = y0 − dy … y1 − 1 in turn; output row y takes its
    // terms once kernel row s = y exists (row y − dy is still in the ring).
    for (int dy = 0; dy <= reach; dy += step) {
      const int dxLo = dy == 0 ? step : -reach;
      if (dxLo > reach) continue;
      for (int sy = y0 - dy; sy < y1; ++sy) {
        const int slot = (sy - (y0 - dy)) % (dy + 1);
        for (int dx = dxLo; dx <= reach; dx += step) {
          // Kernel row s is read at columns x0 − max(dx, 0) … x0 + width + max(−dx, 0) − 1;
          // pairs with s and s + δ in the image are evaluated, the rest is 0.
          float* row = k.data() + size_t(dx + r) * tile.kernelPlane + size_t(slot) * size_t(stride);
          const auto at = [&](int x) { return row + (x - (x0 - r)); };
          const int need0 = x0 - std::max(dx, 0), need1 = x0 + width + std::max(-dx, 0);
          const int valid0 = std::max({need0, 0, -dx});
          const int valid1 = std::min({need1, x1 + std::max(-dx, 0), w, w - dx});
          if (!(sy >= 0 && sy + dy < h && valid0 < valid1)) {
            std::fill(at(need0), at(need1), 0.0f);
            continue;
          }
          std::fill(at(need0), at(valid0), 0.0f);
          kernelRow(guides, kernel, sy, dx, dy, valid0, valid1 - valid0, at(valid0));
          std::fill(at(valid1), at(need1), 0.0f);
        }
        if (sy < y0) continue;
        const RowTerms terms{sy - y0, dy, dxLo, slot, (sy - y0) % (dy + 1)};
        accumulateRow(tile, planes, terms, wide);
      }
    }

    for (int y = 0; y < rows; ++y) {
      const float* sum = acc.data() + size_t(y) * size_t(width);
      for (int j = 0; j < planes; ++j) {
        float* dst = out[size_t(j)] + size_t(y) * size_t(w) + size_t(x0);
        const float* src = acc.data() + size_t(j + 1) * tile.accPlane + size_t(y) * size_t(width);
        for (int i = 0; i < x1 - x0; ++i) dst[i] = src[i] / sum[i];
      }
    }
  }
}

}  // namespace chorus
