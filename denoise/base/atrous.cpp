#include "denoise/base/atrous.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <vector>

#include "denoise/base/atrous_kernel.h"
#include "denoise/base/input_planes.h"
#include "denoise/image/padded_planes.h"
#include "denoise/util/error.h"

namespace chorus {

AtrousParams AtrousParams::fromParams(ParamMap& params) {
  AtrousParams p;
  p.iterations = params.getInt("iterations", p.iterations);
  p.sigmaZ = params.getFloat("sigmaZ", p.sigmaZ);
  p.sigmaN = params.getFloat("sigmaN", p.sigmaN);
  p.sigmaL = params.getFloat("sigmaL", p.sigmaL);
  p.demodulate = params.getBool("demodulate", p.demodulate);
  p.clampFireflies = params.getBool("clampFireflies", p.clampFireflies);
  if (p.iterations < 0 || p.iterations > 10) throw Error("atrous: iterations must be in [0, 10]");
  if (!(p.sigmaZ > 0) || !std::isfinite(p.sigmaZ)) throw Error("atrous: sigmaZ must be > 0");
  if (!(p.sigmaL > 0) || !std::isfinite(p.sigmaL)) throw Error("atrous: sigmaL must be > 0");
  // Powers of two only: w_n is then a chain of squarings, which vectorises.
  if (p.sigmaN != 0 && !(p.sigmaN >= 1 && p.sigmaN <= 1024 && p.sigmaN == std::floor(p.sigmaN) &&
                         std::has_single_bit(unsigned(p.sigmaN))))
    throw Error("atrous: sigmaN must be 0 (off) or a power of two in [1, 1024]");
  return p;
}

namespace {

constexpr std::array<float, 3> kLuminance = {0.2126f, 0.7152f, 0.0722f};
constexpr float kLuminanceEpsilon = 1e-10f;  // SVGF
constexpr float kAlbedoFloor = 1e-3f;        // demodulation
constexpr float kFireflyFactor = 10.0f;      // clamp to this × the 3×3 median luminance

// Guide planes (fixed over the iterations) and state planes (one set per level).
enum GuidePlane {
  kDepth,
  kGradientX,
  kGradientY,
  kNormalX,
  kNormalY,
  kNormalZ,
  kHasNormal,
  kGuidePlanes
};
enum StatePlane { kRed, kGreen, kBlue, kVariance, kStatePlanes };

struct Guide {
  PaddedPlanes planes;          // depth / max depth, σ_z ∇z, unit normal (0 if unknown), 1|0
  bool unknownNormals = false;  // some pixel has no normal
};

// The one-sided difference of smaller magnitude (a single side at the borders, 0 for size 1).
float gentleDifference(const float* z, size_t i, size_t stride, int pos, int size) {
  const bool back = pos > 0, forward = pos + 1 < size;
  const float b = back ? z[i] - z[i - stride] : 0.0f, f = forward ? z[i + stride] - z[i] : 0.0f;
  if (back && forward) return std::abs(b) < std::abs(f) ? b : f;
  return back ? b : f;
}

Guide makeGuide(const SubBuffer& buffer, float sigmaZ) {
  const int w = buffer.width(), h = buffer.height();
  Guide g{PaddedPlanes(w, h, kGuidePlanes)};
  PaddedPlanes& out = g.planes;
  const float scale = 1.0f / maxFiniteDepth(buffer.depth.mean);
  const float* depth = buffer.depth.mean.data();
  const float* normal = buffer.normal.mean.data();
  std::vector<char> unknown(size_t(h), 0);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x), o = out.index(x, y);
      const float z = depth[i];
      out.plane(kDepth)[o] = std::isfinite(z) ? z * scale : 1.0f;  // a miss (∞, NaN) is far
      float n[3];
      for (int c = 0; c < 3; ++c)
        n[c] = std::isfinite(normal[i * 3 + size_t(c)]) ? normal[i * 3 + size_t(c)] : 0.0f;
      const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      const bool known = length > 1e-6f;
      for (int c = 0; c < 3; ++c) out.plane(kNormalX + c)[o] = known ? n[c] / length : 0.0f;
      out.plane(kHasNormal)[o] = known ? 1.0f : 0.0f;
      unknown[size_t(y)] |= !known;
    }
  });
  g.unknownNormals = std::find(unknown.begin(), unknown.end(), 1) != unknown.end();
  const float* z = out.plane(kDepth);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t o = out.index(x, y);
      out.plane(kGradientX)[o] = sigmaZ * gentleDifference(z, o, 1, x, w);
      out.plane(kGradientY)[o] = sigmaZ * gentleDifference(z, o, out.rowStride(), y, h);
    }
  });
  return g;
}

float luminanceOf(const PaddedPlanes& state, size_t i) {
  return kLuminance[0] * state.plane(kRed)[i] + kLuminance[1] * state.plane(kGreen)[i] +
         kLuminance[2] * state.plane(kBlue)[i];
}

// Limits each pixel's luminance to kFireflyFactor × the median of its 3×3 neighbourhood.
void clampFireflies(PaddedPlanes& state) {
  const int w = state.width(), h = state.height();
  std::vector<float> luminance(size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      luminance[size_t(y * w + x)] = luminanceOf(state, state.index(x, y));
  tbb::parallel_for(0, h, [&](int y) {
    std::array<float, 9> window;
    for (int x = 0; x < w; ++x) {
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx >= 0 && qy >= 0 && qx < w && qy < h)
            window[size_t(count++)] = luminance[size_t(qy * w + qx)];
        }
      std::nth_element(window.begin(), window.begin() + count / 2, window.begin() + count);
      const float limit = kFireflyFactor * window[size_t(count / 2)];
      const float l = luminance[size_t(y * w + x)];
      if (!(l > limit)) continue;
      const float factor = limit / l;
      const size_t i = state.index(x, y);
      for (int c = kRed; c <= kBlue; ++c) state.plane(c)[i] *= factor;
      state.plane(kVariance)[i] *= factor * factor;
    }
  });
}

// The row filter for a kernel path: AVX2 where requested and available, else SSE2 (or scalar).
AtrousRowFilter atrousRowFilter(AtrousKernelPath path, int squarings, bool unknownNormals) {
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2 && path == AtrousKernelPath::Widest)
    if (AtrousRowFilter f = selectAtrousRowFilterAvx2(squarings, unknownNormals)) return f;
#endif
#if defined(__SSE2__)
  if (path != AtrousKernelPath::Scalar) return selectRowFilter<Float4x2>(squarings, unknownNormals);
#endif
  return selectRowFilter<Float1>(squarings, unknownNormals);
}

// One à-trous level with tap spacing `step`: state → next (colour and luminance variance).
// `statistics` is scratch for the level's luminance and inverse luminance tolerance.
void atrousLevel(const Guide& g, const AtrousParams& params, AtrousKernelPath path, int step,
                 const PaddedPlanes& state, PaddedPlanes& statistics, PaddedPlanes& next) {
  const int w = state.width(), h = state.height();
  const size_t stride = state.rowStride();
  // Luminance, and 1 / (σ_l √(g3×3 ∗ Var) + ε) with the 3×3 Gaussian (1/4 centre, 1/8 edges,
  // 1/16 corners) clipped and renormalised at the borders.
  tbb::parallel_for(0, h, [&](int y) {
    const float* variance = state.plane(kVariance);
    for (int x = 0; x < w; ++x) {
      const size_t i = state.index(x, y);
      statistics.plane(0)[i] = luminanceOf(state, i);
      float sum = 0, weight = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const float k = (dx == 0 ? 2.0f : 1.0f) * (dy == 0 ? 2.0f : 1.0f);
          sum += k * variance[state.index(qx, qy)];
          weight += k;
        }
      statistics.plane(1)[i] = 1.0f / (params.sigmaL * std::sqrt(sum / weight) + kLuminanceEpsilon);
    }
  });

  AtrousLevelInputs in;
  in.w = w;
  in.h = h;
  in.step = step;
  in.stride = stride;
  in.z = g.planes.plane(kDepth);
  in.gx = g.planes.plane(kGradientX);
  in.gy = g.planes.plane(kGradientY);
  in.nx = g.planes.plane(kNormalX);
  in.ny = g.planes.plane(kNormalY);
  in.nz = g.planes.plane(kNormalZ);
  in.hasNormal = g.planes.plane(kHasNormal);
  in.luminance = statistics.plane(0);
  in.inverseTolerance = statistics.plane(1);
  in.variance = state.plane(kVariance);
  for (int c = 0; c < 3; ++c) in.color[c] = state.plane(kRed + c);
  float* const out[3] = {next.plane(kRed), next.plane(kGreen), next.plane(kBlue)};
  float* outVariance = next.plane(kVariance);
  const int squarings = params.sigmaN > 0 ? std::countr_zero(unsigned(params.sigmaN)) : -1;
  const AtrousRowFilter filterRow = atrousRowFilter(path, squarings, g.unknownNormals);
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) filterRow(in, y, out, outVariance);
  });
}

}  // namespace

Image runAtrous(const SubBuffer& buffer, const AtrousParams& params, AtrousKernelPath path) {
  const int w = buffer.width(), h = buffer.height();
  const float* color = buffer.color.mean.data();
  const float* colorVariance = buffer.color.varianceOfMean.data();
  const float* albedo = buffer.albedo.mean.data();
  // The demodulation divisor max(albedo, 1e-3) (non-finite albedo counts as 0), or 1.
  const auto divisor = [&](size_t e) {
    return params.demodulate ? std::max(std::isfinite(albedo[e]) ? albedo[e] : 0.0f, kAlbedoFloor)
                             : 1.0f;
  };
  // Demodulate; luminance variance (Σ a_c √V_c)², V_c of the demodulated colour.
  PaddedPlanes state(w, h, kStatePlanes);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x), o = state.index(x, y);
      float deviation = 0;
      for (int c = 0; c < 3; ++c) {
        const size_t e = i * 3 + size_t(c);
        const float a = divisor(e), v = colorVariance[e];
        state.plane(kRed + c)[o] = (std::isfinite(color[e]) ? color[e] : 0.0f) / a;
        deviation += kLuminance[size_t(c)] * std::sqrt(std::isfinite(v) && v > 0 ? v : 0.0f) / a;
      }
      state.plane(kVariance)[o] = deviation * deviation;
    }
  });
  if (params.clampFireflies) clampFireflies(state);

  const Guide guide = makeGuide(buffer, params.sigmaZ);
  PaddedPlanes statistics(w, h, 2), next(w, h, kStatePlanes);
  for (int i = 0; i < params.iterations; ++i) {
    atrousLevel(guide, params, path, 1 << i, state, statistics, next);
    std::swap(state, next);
  }

  // Remodulate.
  Image out(w, h, 3);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      for (int c = 0; c < 3; ++c) {
        const float v = state.plane(kRed + c)[state.index(x, y)] * divisor(i * 3 + size_t(c));
        out.data()[i * 3 + size_t(c)] = std::isfinite(v) ? v : 0.0f;
      }
    }
  });
  return out;
}

}  // namespace chorus
