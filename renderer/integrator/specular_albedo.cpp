#include "renderer/integrator/specular_albedo.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "renderer/integrator/fresnel.h"
#include "renderer/integrator/microfacet.h"

namespace chorus::render {
namespace {

// The cosine axis is uniform in x = sqrt(μ): the albedo changes fastest at grazing angles,
// where masking sets in at μ ~ α.
constexpr int kCosineCount = 64;     // μ_i = (i / 63)²
constexpr int kRoughnessCount = 32;  // r_j = (j / 31)², finer near smooth
constexpr int kQuadrature = 32;      // midpoint samples per axis of the VNDF sample square

struct Table {
  // [roughness][cosine]: directional terms; [roughness]: cosine-weighted averages.
  std::vector<SpecularAlbedoTerms> directional;
  std::array<SpecularAlbedoTerms, kRoughnessCount> average;
};

// E1 = ∫ f cos with F ≡ 1, and E5 = the same with F = (1 − wo·h)^5, by sampling visible
// normals: with wi = reflect(wo, h) the estimator f cos / pdf is G2 / G1(wo).
SpecularAlbedoTerms integrate(float cosTheta, float roughness) {
  if (roughness == 0) {
    const float w = schlickWeight(cosTheta);
    return {1.0f - w, w};
  }
  const GgxDistribution ggx = GgxDistribution::fromRoughness(roughness);
  const float mu = std::max(cosTheta, 1e-5f);
  const Vec3f wo{std::sqrt(1.0f - mu * mu), 0.0f, mu};
  double e1 = 0, e5 = 0;
  for (int a = 0; a < kQuadrature; ++a)
    for (int b = 0; b < kQuadrature; ++b) {
      const Vec2f u{(a + 0.5f) / kQuadrature, (b + 0.5f) / kQuadrature};
      const Vec3f h = ggx.sampleVisibleNormal(wo, u);
      const Vec3f wi = reflect(wo, h);
      if (wi.z <= 0) continue;
      const double weight = double(ggx.G(wo, wi)) / double(ggx.G1(wo));
      e1 += weight;
      e5 += weight * double(schlickWeight(dot(wo, h)));
    }
  const double n = double(kQuadrature) * kQuadrature;
  return {float((e1 - e5) / n), float(e5 / n)};
}

// 2 ∫ e(μ) μ dμ = 4 ∫ e(x) x³ dx for e linear in x = sqrt(μ) between the table's samples,
// exactly.
float averageOfPiecewiseLinear(const float* e) {
  const double h = 1.0 / (kCosineCount - 1);
  double sum = 0;
  for (int i = 0; i + 1 < kCosineCount; ++i) {
    const double a = i * h, b = a + h;
    const double x3 = (std::pow(b, 4) - std::pow(a, 4)) / 4;                 // ∫ x³
    const double x3Offset = (std::pow(b, 5) - std::pow(a, 5)) / 5 - a * x3;  // ∫ (x − a) x³
    sum += e[i] * x3 + (e[i + 1] - e[i]) / h * x3Offset;
  }
  return float(4.0 * sum);
}

const Table& table() {
  static const Table instance = [] {
    Table t;
    t.directional.resize(size_t(kRoughnessCount) * kCosineCount);
    tbb::parallel_for(0, kRoughnessCount, [&](int j) {
      const float y = float(j) / (kRoughnessCount - 1);
      const float roughness = y * y;
      for (int i = 0; i < kCosineCount; ++i) {
        const float x = float(i) / (kCosineCount - 1);
        t.directional[size_t(j * kCosineCount + i)] = integrate(x * x, roughness);
      }
    });
    std::vector<float> scale(kCosineCount), bias(kCosineCount);
    for (int j = 0; j < kRoughnessCount; ++j) {
      for (int i = 0; i < kCosineCount; ++i) {
        scale[size_t(i)] = t.directional[size_t(j * kCosineCount + i)].scale;
        bias[size_t(i)] = t.directional[size_t(j * kCosineCount + i)].bias;
      }
      t.average[size_t(j)] = {averageOfPiecewiseLinear(scale.data()),
                              averageOfPiecewiseLinear(bias.data())};
    }
    return t;
  }();
  return instance;
}

// Index and weight of linear interpolation on [0,1] sampled at `count` points.
void gridPosition(float x, int count, int* i, float* w) {
  const float s = std::clamp(x, 0.0f, 1.0f) * float(count - 1);
  *i = std::min(int(s), count - 2);
  *w = s - float(*i);
}

SpecularAlbedoTerms lerp(SpecularAlbedoTerms a, SpecularAlbedoTerms b, float w) {
  return {a.scale + (b.scale - a.scale) * w, a.bias + (b.bias - a.bias) * w};
}

}  // namespace

SpecularAlbedoRow::SpecularAlbedoRow(float roughness) {
  const Table& t = table();
  int j;
  gridPosition(std::sqrt(std::clamp(roughness, 0.0f, 1.0f)), kRoughnessCount, &j, &weight_);
  lower_ = &t.directional[size_t(j * kCosineCount)];
  upper_ = &t.directional[size_t((j + 1) * kCosineCount)];
  average_ = lerp(t.average[size_t(j)], t.average[size_t(j + 1)], weight_);
}

SpecularAlbedoTerms SpecularAlbedoRow::at(float cosTheta) const {
  int i;
  float wi;
  gridPosition(std::sqrt(std::clamp(cosTheta, 0.0f, 1.0f)), kCosineCount, &i, &wi);
  return lerp(lerp(lower_[i], lower_[i + 1], wi), lerp(upper_[i], upper_[i + 1], wi), weight_);
}

SpecularAlbedoTerms specularAlbedo(float cosTheta, float roughness) {
  return SpecularAlbedoRow(roughness).at(cosTheta);
}

SpecularAlbedoTerms specularAlbedoAverage(float roughness) {
  return SpecularAlbedoRow(roughness).average();
}

}  // namespace chorus::render
