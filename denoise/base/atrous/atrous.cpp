#include "denoise/base/atrous/atrous.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "common/error.h"
#include "denoise/base/atrous/atrous_kernel.h"
#include "denoise/base/buffer_variance.h"
#include "denoise/base/input_planes.h"
#include "denoise/base/selection_knee.h"
#include "denoise/base/variance_calibration.h"
#include "denoise/base/variance_estimates.h"
#include "denoise/planes/padded_planes.h"
#include "denoise/util/simd_clones.h"

namespace chorus {

AtrousParams AtrousParams::fromParams(ParamMap& params) {
  AtrousParams p;
  p.iterations = params.getInt("iterations", p.iterations);
  p.sigmaZ = params.getFloat("sigmaZ", p.sigmaZ);
  p.sigmaN = params.getFloat("sigmaN", p.sigmaN);
  p.sigmaL = params.getFloat("sigmaL", p.sigmaL);
  p.demodulate = params.getBool("demodulate", p.demodulate);
  p.clampFireflies = params.getBool("clampFireflies", p.clampFireflies);
  p.symmetricFrom = params.getFloat("symmetricFrom", p.symmetricFrom);
  p.borrow = params.getFloat("borrow", p.borrow);
  p.varianceKnee = params.getFloat("varianceKnee", p.varianceKnee);
  p.calibrationRadius = params.getInt("calibrate", p.calibrationRadius);
  if (p.iterations < kIterationsFromSamples || p.iterations > kMaxIterations)
    throw Error("atrous: iterations must be in [0, " + std::to_string(kMaxIterations) +
                "], or -1 (from the samples per pixel)");
  if (!(p.sigmaZ > 0) || !std::isfinite(p.sigmaZ)) throw Error("atrous: sigmaZ must be > 0");
  if (!(p.sigmaL > 0) || !std::isfinite(p.sigmaL)) throw Error("atrous: sigmaL must be > 0");
  if (!(p.symmetricFrom >= 0)) throw Error("atrous: symmetricFrom must be >= 0");
  if (!(p.borrow >= 0 && p.borrow <= 1)) throw Error("atrous: borrow must be in [0, 1]");
  if (!validKnee(p.varianceKnee)) throw Error("atrous: varianceKnee must be 0 (off) or positive");
  if (p.calibrationRadius < 0 || p.calibrationRadius > kMaxCalibrationRadius)
    throw Error("atrous: calibrate must be in [0, " + std::to_string(kMaxCalibrationRadius) + "]");
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
constexpr float kEmitterAlbedo = 0.02f;      // below this in every channel: not demodulated…
constexpr int kEmitterGuard = 1;             // …and neither are its neighbours within this
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

Guide makeGuide(const SubBuffer& buffer, float sigmaZ, int margin) {
  const int w = buffer.width(), h = buffer.height();
  Guide g{PaddedPlanes(w, h, kGuidePlanes, margin)};
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
  if (cpuHasAvx512f() && path == AtrousKernelPath::Widest)
    if (AtrousRowFilter f = selectAtrousRowFilterAvx512(squarings, unknownNormals)) return f;
  if (cpuHasAvx2() && (path == AtrousKernelPath::Widest || path == AtrousKernelPath::Avx2))
    if (AtrousRowFilter f = selectAtrousRowFilterAvx2(squarings, unknownNormals)) return f;
#endif
#if defined(__SSE2__)
  if (path != AtrousKernelPath::Scalar)
    return selectRowFilter<Pair<Float4>>(squarings, unknownNormals);
#endif
  return selectRowFilter<Float1>(squarings, unknownNormals);
}

#if defined(__SSE2__)
using StatisticsLanes = Float4;
#else
using StatisticsLanes = Float1;
#endif

enum KneePlane { kKneedVariance, kKneeDivisor, kKneePlanes };

// Scratch of the variance knee, allocated once per run: the level's luminance (contiguous, for
// kneeLevel) and, in the state's padded layout, its variance divided by each pixel's knee
// divisor and the divisors.
struct KneeScratch {
  std::vector<float> luminance;
  PaddedPlanes planes;
};

// Fills `scratch` for this level (selection_knee.h; a pixel's level: its luminance); false
// where the knee is off (knee 0 or a black level), and the plain variance is blurred.
bool kneedVariance(const PaddedPlanes& state, float knee, KneeScratch& scratch) {
  const int w = state.width(), h = state.height();
  scratch.luminance.resize(size_t(w) * size_t(h));
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x)
      scratch.luminance[size_t(y) * size_t(w) + size_t(x)] = luminanceOf(state, state.index(x, y));
  });
  const double level = kneeLevel(scratch.luminance, knee);
  if (!(level > 0)) return false;
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = state.index(x, y);
      const float d =
          float(kneeDivisor(scratch.luminance[size_t(y) * size_t(w) + size_t(x)], level));
      scratch.planes.plane(kKneeDivisor)[i] = d;
      scratch.planes.plane(kKneedVariance)[i] = state.plane(kVariance)[i] / d;
    }
  });
  return true;
}

// Luminance of rows [first, last) and their inverse tolerance 1 / (σ_l √V + ε_l), with
// V = max(borrow · B, min(Var, B)) and B = g3×3 ∗ Var (atrous.h; borrow 1: V = B), the 3×3
// Gaussian (1/4 centre, 1/8 edges, 1/16 corners) clipped and renormalised at the borders,
// applied separably ([1 2 1] / 4 per axis, / 3 where one side is missing, / 2 with none). Each
// row is smoothed horizontally once, into a ring of three rows. With `kneed`, B is smoothed from
// its variance in relative units and multiplied by the pixel's own divisor.
void levelStatistics(const PaddedPlanes& state, const PaddedPlanes* kneed, float sigmaL,
                     float borrow, int first, int last, PaddedPlanes& statistics) {
  const int w = state.width(), h = state.height();
  const float* variance = kneed ? kneed->plane(kKneedVariance) : state.plane(kVariance);
  std::vector<float> scratch(size_t(3 * w));
  // Horizontally smoothed variance of rows y − 1, y, y + 1 (zeros outside the image).
  float* ring[3] = {scratch.data(), scratch.data() + w, scratch.data() + 2 * w};
  const auto axisNorm = [](int pos, int size) {
    return 1.0f / (2.0f + (pos > 0 ? 1.0f : 0.0f) + (pos + 1 < size ? 1.0f : 0.0f));
  };
  const auto smoothRow = [&](int qy, float* out) {
    if (qy < 0 || qy >= h) {
      std::fill(out, out + w, 0.0f);
      return;
    }
    const float* v = variance + state.index(0, qy);  // columns −1 and w read the zero margin
    for (int x = 0; x < w; ++x) out[x] = v[x - 1] + 2.0f * v[x] + v[x + 1];
    out[0] *= axisNorm(0, w);
    for (int x = 1; x < w - 1; ++x) out[x] *= 0.25f;
    if (w > 1) out[w - 1] *= axisNorm(w - 1, w);
  };
  smoothRow(first - 1, ring[0]);
  smoothRow(first, ring[1]);
  for (int y = first; y < last; ++y) {
    smoothRow(y + 1, ring[2]);
    const float yNorm = axisNorm(y, h);
    float* luminance = statistics.plane(0) + state.index(0, y);
    float* tolerance = statistics.plane(1) + state.index(0, y);
    const float* ownVariance = state.plane(kVariance) + state.index(0, y);
    const float* divisor = kneed ? kneed->plane(kKneeDivisor) + state.index(0, y) : nullptr;
    const float* color[3] = {state.plane(kRed) + state.index(0, y),
                             state.plane(kGreen) + state.index(0, y),
                             state.plane(kBlue) + state.index(0, y)};
    // In lanes: the compiler does not vectorise this loop by itself (the rows might alias).
    const auto toleranceOf = [&](auto lanes, int x) {
      using F = decltype(lanes);
      (F::broadcast(kLuminance[0]) * F::load(color[0] + x) +
       F::broadcast(kLuminance[1]) * F::load(color[1] + x) +
       F::broadcast(kLuminance[2]) * F::load(color[2] + x))
          .store(luminance + x);
      F g = (F::load(ring[0] + x) + F::broadcast(2.0f) * F::load(ring[1] + x) +
             F::load(ring[2] + x)) *
            F::broadcast(yNorm);
      if (divisor) g = g * F::load(divisor + x);
      if (borrow < 1) {
        const F own = F::load(ownVariance + x), share = F::broadcast(borrow) * g;
        const F lowered = g - max0(g - own);  // min(own, g)
        g = share + max0(lowered - share);
      }
      (F::broadcast(1.0f) / (F::broadcast(sigmaL) * sqrt(g) + F::broadcast(kLuminanceEpsilon)))
          .store(tolerance + x);
    };
    int x = 0;
    for (; x + StatisticsLanes::kWidth <= w; x += StatisticsLanes::kWidth)
      toleranceOf(StatisticsLanes{}, x);
    for (; x < w; ++x) toleranceOf(Float1{}, x);
    std::rotate(ring, ring + 1, ring + 3);  // row y + 1 becomes the centre
  }
}

// One à-trous level with tap spacing `step`: state → next (colour and luminance variance).
// `statistics` is scratch for the level's luminance and inverse luminance tolerance, `knee`
// for the variance knee (unused when params.varianceKnee is 0).
void atrousLevel(const Guide& g, const AtrousParams& params, bool symmetric, AtrousKernelPath path,
                 int step, const PaddedPlanes& state, PaddedPlanes& statistics, KneeScratch& knee,
                 PaddedPlanes& next, const std::vector<float>& inside) {
  const int w = state.width(), h = state.height();
  const bool kneed = params.varianceKnee > 0 && kneedVariance(state, params.varianceKnee, knee);
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    levelStatistics(state, kneed ? &knee.planes : nullptr, params.sigmaL,
                    symmetric ? 1.0f : params.borrow, rows.begin(), rows.end(), statistics);
  });

  // Pointers to pixel (0, 0) of each plane (all planes share the padded layout).
  const size_t origin = state.index(0, 0);
  AtrousLevelInputs in;
  in.w = w;
  in.h = h;
  in.step = step;
  in.stride = ptrdiff_t(state.rowStride());
  in.inside = inside.data() + state.margin();
  in.z = g.planes.plane(kDepth) + origin;
  in.gx = g.planes.plane(kGradientX) + origin;
  in.gy = g.planes.plane(kGradientY) + origin;
  in.nx = g.planes.plane(kNormalX) + origin;
  in.ny = g.planes.plane(kNormalY) + origin;
  in.nz = g.planes.plane(kNormalZ) + origin;
  in.hasNormal = g.planes.plane(kHasNormal) + origin;
  in.luminance = statistics.plane(0) + origin;
  in.inverseTolerance = statistics.plane(1) + origin;
  in.neighbourTolerance = statistics.plane(symmetric ? 1 : 2) + origin;
  in.variance = state.plane(kVariance) + origin;
  for (int c = 0; c < 3; ++c) in.color[c] = state.plane(kRed + c) + origin;
  float* const out[3] = {next.plane(kRed) + origin, next.plane(kGreen) + origin,
                         next.plane(kBlue) + origin};
  float* outVariance = next.plane(kVariance) + origin;
  const int squarings = params.sigmaN > 0 ? std::countr_zero(unsigned(params.sigmaN)) : -1;
  const AtrousRowFilter filterRow = atrousRowFilter(path, squarings, g.unknownNormals);
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) filterRow(in, y, out, outVariance);
  });
}

// Demodulation divisors, interleaved RGB like the albedo: max(albedo, 1e-3) (non-finite albedo
// counts as 0) — except near a pixel whose albedo is (nearly) black in every channel, where they
// are 1. With the chorus renderer's features an emitter seen directly records its material's
// albedo (black for a pure light), so its radiance divided by the albedo floor is enormous, and
// pixels that mix emitter and surface samples take huge demodulated values and variances that
// leak into their neighbours (measured on the Cornell box: relMSE ×6 at 64 spp). Filtering those
// pixels as radiance avoids it; Tungsten instead records 1 + emission as an emitter's albedo,
// which has the same effect. The guard square is dilated separably. Computed once per run: the
// demodulation and the remodulation both read them.
std::vector<float> demodulationDivisors(const SubBuffer& buffer, bool demodulate) {
  const int w = buffer.width(), h = buffer.height();
  const size_t pixels = size_t(w) * size_t(h);
  std::vector<float> divisors(pixels * 3);
  if (!demodulate) {
    std::fill(divisors.begin(), divisors.end(), 1.0f);
    return divisors;
  }
  const float* albedo = buffer.albedo.mean.data();
  // nearBlack: some pixel within kEmitterGuard columns on the same row is black.
  std::vector<char> nearBlack(pixels);
  tbb::parallel_for(0, h, [&](int y) {
    std::vector<char> black(size_t(w) + 2 * kEmitterGuard, 0);  // with a guard band each side
    const float* a = albedo + size_t(y) * size_t(w) * 3;
    for (int x = 0; x < w; ++x) {
      const float brightest =
          std::max(std::max(0.0f, finiteOrZero(a[3 * x])),
                   std::max(finiteOrZero(a[3 * x + 1]), finiteOrZero(a[3 * x + 2])));
      black[size_t(x + kEmitterGuard)] = brightest < kEmitterAlbedo;
    }
    char* row = nearBlack.data() + size_t(y) * size_t(w);
    for (int x = 0; x < w; ++x) {
      char near = 0;
      for (int d = 0; d <= 2 * kEmitterGuard; ++d) near |= black[size_t(x + d)];
      row[x] = near;
    }
  });
  tbb::parallel_for(0, h, [&](int y) {
    const char* near[2 * kEmitterGuard + 1];
    int rows = 0;
    for (int qy = std::max(0, y - kEmitterGuard); qy <= std::min(h - 1, y + kEmitterGuard); ++qy)
      near[rows++] = nearBlack.data() + size_t(qy) * size_t(w);
    const size_t first = size_t(y) * size_t(w);
    const float* a = albedo + first * 3;
    float* out = divisors.data() + first * 3;
    for (int x = 0; x < w; ++x) {
      char guarded = 0;
      for (int r = 0; r < rows; ++r) guarded |= near[r][x];
      for (int c = 0; c < 3; ++c) {
        const float v = a[3 * x + c];
        const float floored = std::isfinite(v) ? std::max(v, kAlbedoFloor) : kAlbedoFloor;
        out[3 * x + c] = guarded ? 1.0f : floored;
      }
    }
  });
  return divisors;
}

}  // namespace

int iterationsForSamples(double spp) {
  if (!(spp > 0)) return 5;
  return int(std::clamp(std::lround(9.0 - std::log2(spp)), 2L, 5L));
}

Image runAtrous(const SubBuffer& buffer, const AtrousParams& given, AtrousKernelPath path,
                double sampleShare, const Image* colorVariance) {
  const int w = buffer.width(), h = buffer.height();
  const double renderSpp = renderSamplesPerPixel(buffer, sampleShare);
  AtrousParams params = given;
  if (params.iterations == AtrousParams::kIterationsFromSamples)
    params.iterations = iterationsForSamples(renderSpp);
  const bool symmetric = renderSpp >= params.symmetricFrom;
  const float* color = buffer.color.mean.data();
  const Image& variance = colorVariance ? *colorVariance : buffer.color.varianceOfMean;
  if (!variance.sameShape(buffer.color.mean))
    throw std::invalid_argument("runAtrous: the colour variance's shape differs");
  const std::vector<float> divisors = demodulationDivisors(buffer, params.demodulate);
  // Taps reach 2·2^(iterations−1) pixels past the borders: zero margins that wide.
  const int margin = 1 << params.iterations;
  // Demodulate; luminance variance (Σ a_c √V_c)², V_c of the demodulated colour.
  PaddedPlanes state(w, h, kStatePlanes, margin);
  tbb::parallel_for(0, h, [&](int y) {
    const size_t first = size_t(y) * size_t(w) * 3, o = state.index(0, y);
    const float *m = color + first, *v = variance.data() + first, *d = divisors.data() + first;
    float* rgb[3] = {state.plane(kRed) + o, state.plane(kGreen) + o, state.plane(kBlue) + o};
    float* variance = state.plane(kVariance) + o;
    for (int x = 0; x < w; ++x) {
      float deviation = 0;
      for (int c = 0; c < 3; ++c) {
        const size_t e = size_t(3 * x + c);
        const float inverse = 1.0f / d[e];
        rgb[c][x] = finiteOrZero(m[e]) * inverse;
        const float positive = v[e] > 0 && v[e] <= std::numeric_limits<float>::max() ? v[e] : 0.0f;
        deviation += kLuminance[size_t(c)] * std::sqrt(positive) * inverse;
      }
      variance[x] = deviation * deviation;
    }
  });
  if (params.clampFireflies) clampFireflies(state);

  const Guide guide = makeGuide(buffer, params.sigmaZ, margin);
  // Planes 0 and 1: a level's luminance and inverse tolerance; without the symmetric rule a
  // plane 2 of zeros stands for the neighbours' tolerance (max(t_p, 0) = t_p).
  PaddedPlanes statistics(w, h, symmetric ? 2 : 3, margin), next(w, h, kStatePlanes, margin);
  if (!symmetric)
    for (int y = 0; y < h; ++y) std::fill_n(statistics.plane(2) + statistics.index(0, y), w, 0.0f);
  std::vector<float> inside(size_t(w + 2 * margin), 0.0f);
  std::fill(inside.begin() + margin, inside.begin() + margin + w, 1.0f);
  KneeScratch knee;
  if (params.varianceKnee > 0) knee.planes = PaddedPlanes(w, h, kKneePlanes, margin);
  for (int i = 0; i < params.iterations; ++i) {
    atrousLevel(guide, params, symmetric, path, 1 << i, state, statistics, knee, next, inside);
    std::swap(state, next);
  }

  // Remodulate.
  Image out(w, h, 3);
  tbb::parallel_for(0, h, [&](int y) {
    const size_t first = size_t(y) * size_t(w) * 3, o = state.index(0, y);
    const float* d = divisors.data() + first;
    float* row = out.data() + first;
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        row[3 * x + c] = finiteOrZero(state.plane(kRed + c)[o + size_t(x)] * d[3 * x + c]);
  });
  return out;
}

Image Atrous::run(const DenoiseInput& input) const {
  const Image calibrated = calibratedWholeColorVariance(input, params_.calibrationRadius);
  const Image& recorded = calibrated.empty() ? input.whole.color.varianceOfMean : calibrated;
  if (!hasOneSamplePixels(input.whole))
    return runAtrous(input.whole, params_, AtrousKernelPath::Widest, input.sampleShare, &recorded);
  // One-sample pixels (1 spp) record variance 0, which would stop the luminance weight at every
  // difference: there the spread of their neighbourhood instead.
  const Image variance = spatialVarianceWhereOneSample(input.whole, Quantity::Color, recorded);
  return runAtrous(input.whole, params_, AtrousKernelPath::Widest, input.sampleShare, &variance);
}

}  // namespace chorus
