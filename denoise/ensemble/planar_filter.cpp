#include "denoise/ensemble/planar_filter.h"

#include <algorithm>

#include "denoise/util/fast_exp.h"
#include "denoise/util/simd_clones.h"

namespace chorus {
namespace {

constexpr float kVarianceFloor = 1e-6f;

// Kernel values k[i] for the pixels x = x0 + i (i < count) of row y and offset (dx, dy): the
// distances first (a loop that vectorises), then their exponentials.
// Pointers start at p = (x0, y) and q = (x0 + dx, y + dy); plain int indexing so that the
// loops vectorise.
CHORUS_SIMD_CLONES void kernelRow(const PlanarGuides& g, const BilateralKernel& kernel, int y, int dx, int dy, int x0,
               int count, float* __restrict k) {
  const size_t pixels = size_t(g.width) * size_t(g.height);
  const size_t rowP = size_t(y) * size_t(g.width) + size_t(x0);
  const size_t rowQ = size_t(y + dy) * size_t(g.width) + size_t(x0 + dx);
  const float spatial = kernel.kSpatial * float(dx * dx + dy * dy);
  const float kn = kernel.kNormal, ka = kernel.kAlbedo, kc = kernel.kColor;
  const float *n0p = g.normal.data() + rowP, *n1p = n0p + pixels, *n2p = n1p + pixels;
  const float *n0q = g.normal.data() + rowQ, *n1q = n0q + pixels, *n2q = n1q + pixels;
  const float *a0p = g.albedo.data() + rowP, *a1p = a0p + pixels, *a2p = a1p + pixels;
  const float *a0q = g.albedo.data() + rowQ, *a1q = a0q + pixels, *a2q = a1q + pixels;
  if (kc > 0) {
    const float *z0p = g.color.data() + rowP, *z1p = z0p + pixels, *z2p = z1p + pixels;
    const float *z0q = g.color.data() + rowQ, *z1q = z0q + pixels, *z2q = z1q + pixels;
    const float *v0p = g.variance.data() + rowP, *v1p = v0p + pixels, *v2p = v1p + pixels;
    const float *v0q = g.variance.data() + rowQ, *v1q = v0q + pixels, *v2q = v1q + pixels;
    for (int i = 0; i < count; ++i) {
      const float dn0 = n0p[i] - n0q[i], dn1 = n1p[i] - n1q[i], dn2 = n2p[i] - n2q[i];
      const float da0 = a0p[i] - a0q[i], da1 = a1p[i] - a1q[i], da2 = a2p[i] - a2q[i];
      const float dz0 = z0p[i] - z0q[i], dz1 = z1p[i] - z1q[i], dz2 = z2p[i] - z2q[i];
      // Σ_c dz_c²/s_c with one division: (a·s1·s2 + b·s0·s2 + c·s0·s1) / (s0·s1·s2); the
      // guide's bounds (|z| ≤ 1e6, V ≤ 1e12) keep every product finite.
      const float s0 = v0p[i] + v0q[i] + kVarianceFloor, s1 = v1p[i] + v1q[i] + kVarianceFloor,
                  s2 = v2p[i] + v2q[i] + kVarianceFloor;
      const float color =
          (dz0 * dz0 * (s1 * s2) + dz1 * dz1 * (s0 * s2) + dz2 * dz2 * (s0 * s1)) / (s0 * s1 * s2);
      k[i] = (spatial + kn * (dn0 * dn0 + dn1 * dn1 + dn2 * dn2) +
              ka * (da0 * da0 + da1 * da1 + da2 * da2) + kc * color);
    }
  } else {
    for (int i = 0; i < count; ++i) {
      const float dn0 = n0p[i] - n0q[i], dn1 = n1p[i] - n1q[i], dn2 = n2p[i] - n2q[i];
      const float da0 = a0p[i] - a0q[i], da1 = a1p[i] - a1q[i], da2 = a2p[i] - a2q[i];
      k[i] = (spatial + kn * (dn0 * dn0 + dn1 * dn1 + dn2 * dn2) +
              ka * (da0 * da0 + da1 * da1 + da2 * da2));
    }
  }
  fastExpNegated(k, k, count);
}

}  // namespace

CHORUS_SIMD_CLONES void filterPlaneRows(const PlanarGuides& guides,
                                        const BilateralKernel& kernel,
                                        std::span<const float* const> in, int inY0, int y0,
                                        int y1, std::span<float* const> out) {
  const int w = guides.width, h = guides.height, r = std::max(0, kernel.radius);
  const size_t planes = in.size();
  // The kernel is symmetric, k(s, s+δ) = k(s+δ, s) bit for bit, so it is evaluated once per
  // pair for the offsets δ of one half-plane and applied in both directions. Every output value
  // still receives its terms in one fixed order (centre, then per δ: q = p + δ, q = p − δ), so
  // results do not depend on how the image is cut into tiles. Tiles are column blocks of the
  // requested rows, small enough for the accumulators to stay in cache.
  constexpr int kBlock = 128;
  const int rows = y1 - y0;
  const int stride = kBlock + 2 * r;  // kernel buffer row: columns bx0 − r … bx1 + r
  std::vector<float> k(size_t(rows + r) * size_t(stride));
  std::vector<float> weightSum(size_t(rows) * kBlock), acc(planes * size_t(rows) * kBlock);
  const auto inRow = [&](size_t j, int y) { return in[j] + size_t(y - inY0) * size_t(w); };
  for (int bx0 = 0; bx0 < w; bx0 += kBlock) {
    const int bx1 = std::min(w, bx0 + kBlock), bw = bx1 - bx0;
    // Centre tap: k(p, p) = exp(0) = 1.
    for (int y = y0; y < y1; ++y) {
      float* sum = weightSum.data() + size_t(y - y0) * kBlock;
      for (int i = 0; i < bw; ++i) sum[i] = 1.0f;
      for (size_t j = 0; j < planes; ++j) {
        const float* src = inRow(j, y) + bx0;
        float* dst = acc.data() + (j * size_t(rows) + size_t(y - y0)) * kBlock;
        for (int i = 0; i < bw; ++i) dst[i] = src[i];
      }
    }
    for (int dy = 0; dy <= r; ++dy) {
      for (int dx = dy == 0 ? 1 : -r; dx <= r; ++dx) {
        // Pairs (s, s + δ) with s or s + δ in the tile and both inside the image.
        const int sy0 = std::max(0, y0 - dy), sy1 = std::min(y1, h - dy);
        const int sx0 = std::max({0, -dx, std::min(bx0, bx0 - dx)});
        const int sx1 = std::min({w, w - dx, std::max(bx1, bx1 - dx)});
        if (sy0 >= sy1 || sx0 >= sx1) continue;
        // k buffer: row sy − sy0, column sx − (bx0 − r).
        const int kx0 = sx0 - (bx0 - r);
        for (int sy = sy0; sy < sy1; ++sy)
          kernelRow(guides, kernel, sy, dx, dy, sx0, sx1 - sx0,
                    k.data() + size_t(sy - sy0) * size_t(stride) + size_t(kx0));
        // p = s, q = p + δ: rows y ∈ [y0, y1) ∩ [sy0, sy1), columns x ∈ [bx0, bx1) ∩ [sx0, sx1).
        const int px0 = std::max(bx0, sx0), px1 = std::min(bx1, sx1);
        for (int y = std::max(y0, sy0); y < std::min(y1, sy1) && px0 < px1; ++y) {
          const float* kp = k.data() + size_t(y - sy0) * size_t(stride) + size_t(px0 - (bx0 - r));
          const int count = px1 - px0, offset = px0 - bx0;
          float* sum = weightSum.data() + size_t(y - y0) * kBlock + size_t(offset);
          for (int i = 0; i < count; ++i) sum[i] += kp[i];
          for (size_t j = 0; j < planes; ++j) {
            const float* src = inRow(j, y + dy) + (px0 + dx);
            float* dst = acc.data() + (j * size_t(rows) + size_t(y - y0)) * kBlock + size_t(offset);
            for (int i = 0; i < count; ++i) dst[i] += kp[i] * src[i];
          }
        }
        // p = s + δ, q = p − δ: s rows y − dy ∈ [sy0, sy1), columns x − dx ∈ [sx0, sx1).
        const int mx0 = std::max(bx0, sx0 + dx), mx1 = std::min(bx1, sx1 + dx);
        for (int y = std::max(y0, sy0 + dy); y < std::min(y1, sy1 + dy) && mx0 < mx1; ++y) {
          const float* km =
              k.data() + size_t(y - dy - sy0) * size_t(stride) + size_t(mx0 - dx - (bx0 - r));
          const int count = mx1 - mx0, offset = mx0 - bx0;
          float* sum = weightSum.data() + size_t(y - y0) * kBlock + size_t(offset);
          for (int i = 0; i < count; ++i) sum[i] += km[i];
          for (size_t j = 0; j < planes; ++j) {
            const float* src = inRow(j, y - dy) + (mx0 - dx);
            float* dst = acc.data() + (j * size_t(rows) + size_t(y - y0)) * kBlock + size_t(offset);
            for (int i = 0; i < count; ++i) dst[i] += km[i] * src[i];
          }
        }
      }
    }
    for (int y = y0; y < y1; ++y) {
      const float* sum = weightSum.data() + size_t(y - y0) * kBlock;
      for (size_t j = 0; j < planes; ++j) {
        float* dst = out[j] + size_t(y - y0) * size_t(w) + size_t(bx0);
        const float* src = acc.data() + (j * size_t(rows) + size_t(y - y0)) * kBlock;
        for (int i = 0; i < bw; ++i) dst[i] = src[i] / sum[i];
      }
    }
  }
}

}  // namespace chorus
