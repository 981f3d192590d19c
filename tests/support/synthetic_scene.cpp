#include "tests/support/synthetic_scene.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace chorus::test {
namespace {

struct Vec3 {
  double x = 0, y = 0, z = 0;
};
Vec3 operator*(const Vec3& a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
double dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
Vec3 normalize(const Vec3& a) {
  return a * (1.0 / std::sqrt(dot(a, a)));
}

// What a camera ray sees at one point of the image plane.
struct SurfacePoint {
  Vec3 albedo, normal;
  double depth = 0;
  double visibility = 0;
  Vec3 radiance;
  int region = 0;  // differs across albedo, normal and object edges
};

const Vec3 kLightDirection = normalize({-0.5, 0.4, 0.75});
constexpr double kIrradiance = 1.2, kAmbient = 0.1;

SurfacePoint evaluate(double u, double v) {
  SurfacePoint s;
  const double du = (u - 0.62) / 0.2, dv = (v - 0.4) / 0.2, r2 = du * du + dv * dv;
  if (r2 < 1.0) {
    // Sphere: smooth normals, closer than the plane.
    const double nz = std::sqrt(1.0 - r2);
    s.normal = {du, -dv, nz};
    s.depth = 1.2 - 0.2 * nz;
    s.albedo = {0.85, 0.75, 0.25};
    s.region = 1000;
  } else {
    // Plane: normal crease along a diagonal, albedo edge at u = 0.5, stripes at the bottom.
    const bool creaseSide = u + 0.5 * (v - 0.5) > 0.3;
    s.normal = creaseSide ? Vec3{0, 0, 1} : normalize({0.5, 0, 1});
    s.depth = 2.0 + v;
    int albedoRegion;
    if (v > 0.8) {
      const bool bright = (int(std::floor(u * 12.0)) % 2) == 0;
      s.albedo = bright ? Vec3{0.9, 0.9, 0.9} : Vec3{0.08, 0.08, 0.08};
      albedoRegion = 2 + int(std::floor(u * 12.0));
    } else {
      s.albedo = u < 0.5 ? Vec3{0.8, 0.35, 0.15} : Vec3{0.15, 0.4, 0.8};
      albedoRegion = u < 0.5 ? 0 : 1;
    }
    s.region = albedoRegion * 2 + (creaseSide ? 1 : 0);
  }
  const double cosine = dot(s.normal, kLightDirection);
  s.visibility = cosine > 0 ? 1.0 : 0.0;
  s.radiance = s.albedo * (kIrradiance * std::max(0.0, cosine) + kAmbient);
  return s;
}

// SplitMix64: a small, fast generator with independent streams from hashed seeds.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
  double exponential() { return -std::log(1.0 - uniform()); }
  double gaussian() {
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  uint64_t state_;
};

uint64_t streamSeed(uint32_t seed, int subBuffer, size_t pixel) {
  Rng mix(uint64_t(seed) * 0x100000001B3ull ^ (uint64_t(subBuffer) << 48) ^ uint64_t(pixel));
  mix.next();
  return mix.next();
}

// Welford accumulation of one quantity's samples in one pixel.
template <int C>
struct Welford {
  double n = 0, mean[C] = {}, m2[C] = {};
  void add(const double* x) {
    n += 1;
    for (int c = 0; c < C; ++c) {
      const double delta = x[c] - mean[c];
      mean[c] += delta / n;
      m2[c] += delta * (x[c] - mean[c]);
    }
  }
  void store(MeanVariance& out, size_t pixel) const {
    for (int c = 0; c < C; ++c) {
      out.mean.data()[pixel * C + size_t(c)] = float(mean[c]);
      out.varianceOfMean.data()[pixel * C + size_t(c)] =
          n >= 2 ? float(m2[c] / (n * (n - 1))) : 0.0f;
    }
  }
};

void simulatePixel(const SyntheticSceneOptions& o, int x, int y, int k, SubBuffer& sub) {
  const size_t pixel = size_t(y) * size_t(o.width) + size_t(x);
  Rng rng(streamSeed(o.seed, k, pixel));
  Welford<3> color, albedo, normal;
  Welford<1> depth, visibility;
  for (int i = 0; i < o.samplesPerSubBuffer; ++i) {
    const double u = (x + rng.uniform()) / o.width, v = (y + rng.uniform()) / o.height;
    const SurfacePoint s = evaluate(u, v);
    double factor = rng.exponential();
    if (rng.uniform() < o.fireflyProbability) factor *= o.fireflyScale;
    double c[3] = {s.radiance.x * factor, s.radiance.y * factor, s.radiance.z * factor};
    if (o.constantColor)
      for (int ch = 0; ch < 3; ++ch) c[ch] = (*o.constantColor)[size_t(ch)];
    double a[3] = {s.albedo.x, s.albedo.y, s.albedo.z};
    double n[3] = {s.normal.x, s.normal.y, s.normal.z};
    if (o.featureNoise > 0)
      for (int ch = 0; ch < 3; ++ch) {
        a[ch] += o.featureNoise * rng.gaussian();
        n[ch] += o.featureNoise * rng.gaussian();
      }
    color.add(c);
    albedo.add(a);
    normal.add(n);
    depth.add(&s.depth);
    visibility.add(&s.visibility);
  }
  color.store(sub.color, pixel);
  albedo.store(sub.albedo, pixel);
  normal.store(sub.normal, pixel);
  depth.store(sub.depth, pixel);
  visibility.store(sub.visibility, pixel);
  sub.sampleCount.data()[pixel] = float(o.samplesPerSubBuffer);
}

// Pixel integral of radiance and features on a g×g grid; returns whether regions differ.
bool integratePixel(int x, int y, int g, const SyntheticSceneOptions& o, double out[10]) {
  for (int i = 0; i < 10; ++i) out[i] = 0;
  int firstRegion = -1;
  bool straddles = false;
  for (int j = 0; j < g; ++j)
    for (int i = 0; i < g; ++i) {
      const SurfacePoint s =
          evaluate((x + (i + 0.5) / g) / o.width, (y + (j + 0.5) / g) / o.height);
      if (firstRegion < 0) firstRegion = s.region;
      straddles |= s.region != firstRegion;
      const double values[10] = {s.radiance.x, s.radiance.y, s.radiance.z, s.albedo.x, s.albedo.y,
                                 s.albedo.z,   s.normal.x,   s.normal.y,   s.normal.z, s.depth};
      for (int c = 0; c < 10; ++c) out[c] += values[c] / (g * g);
    }
  return straddles;
}

}  // namespace

SyntheticScene makeSyntheticScene(const SyntheticSceneOptions& o) {
  if (o.width <= 0 || o.height <= 0 || o.subBuffers <= 0 || o.samplesPerSubBuffer <= 0)
    throw std::invalid_argument("makeSyntheticScene: sizes and counts must be positive");
  const int w = o.width, h = o.height;

  std::vector<SubBuffer> subs;
  for (int k = 0; k < o.subBuffers; ++k) subs.push_back(SubBuffer::zeros(w, h));
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y)
      for (int k = 0; k < o.subBuffers; ++k)
        for (int x = 0; x < w; ++x) simulatePixel(o, x, y, k, subs[size_t(k)]);
  });

  SyntheticScene scene;
  scene.buffers = SampleBuffers(std::move(subs));
  scene.truth = Image(w, h, 3);
  scene.albedo = Image(w, h, 3);
  scene.normal = Image(w, h, 3);
  scene.depth = Image(w, h, 1);
  Image straddles(w, h, 1);
  const double noiseMean = 1.0 + o.fireflyProbability * (o.fireflyScale - 1.0);
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y)
      for (int x = 0; x < w; ++x) {
        double v[10];
        const bool edge = integratePixel(x, y, 4, o, v) && integratePixel(x, y, 16, o, v);
        straddles(x, y, 0) = edge ? 1.0f : 0.0f;
        for (int c = 0; c < 3; ++c) {
          scene.truth(x, y, c) =
              o.constantColor ? (*o.constantColor)[size_t(c)] : float(v[c] * noiseMean);
          scene.albedo(x, y, c) = float(v[3 + c]);
          scene.normal(x, y, c) = float(v[6 + c]);
        }
        scene.depth(x, y, 0) = float(v[9]);
      }
  });

  scene.edgeMask = Image(w, h, 1);
  const int r = o.edgeRadius;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool near = false;
      for (int dy = -r; dy <= r && !near; ++dy)
        for (int dx = -r; dx <= r && !near; ++dx) {
          const int qx = x + dx, qy = y + dy;
          near = qx >= 0 && qx < w && qy >= 0 && qy < h && straddles(qx, qy, 0) > 0;
        }
      scene.edgeMask(x, y, 0) = near ? 1.0f : 0.0f;
      scene.edgePixelCount += near ? 1 : 0;
    }
  return scene;
}

double maskedRelMse(const Image& image, const Image& reference, const Image& mask, double epsilon) {
  if (!image.sameShape(reference) || !image.sameSize(mask))
    throw std::invalid_argument("maskedRelMse: shapes differ");
  double sum = 0;
  size_t count = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      if (mask(x, y, 0) <= 0.5f) continue;
      for (int c = 0; c < image.channels(); ++c) {
        const double r = reference(x, y, c), d = image(x, y, c) - r;
        sum += d * d / (r * r + epsilon);
        ++count;
      }
    }
  return count ? sum / double(count) : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace chorus::test
