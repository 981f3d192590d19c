#include "renderer/integrator/specular_albedo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>
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

// Rows are integrated on first use: a scene needs only the two rows around each of its
// roughness values, and the whole table took ≈ 0.07 s of every start-up with a specular layer.
struct Table {
  // [roughness][cosine]: directional terms; [roughness]: cosine-weighted averages.
  std::vector<SpecularAlbedoTerms> directional =
      std::vector<SpecularAlbedoTerms>(size_t(kRoughnessCount) * kCosineCount);
  std::array<SpecularAlbedoTerms, kRoughnessCount> average{};
  std::array<std::once_flag, kRoughnessCount> integrated;
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

// Row j (its kCosineCount terms) and its average, integrated by the first thread that needs it.
// Serially: a parallel loop inside call_once could pick up another task that waits on the
// same row.
const SpecularAlbedoTerms* tableRow(int j, SpecularAlbedoTerms* average) {
  static Table t;
  SpecularAlbedoTerms* row = &t.directional[size_t(j * kCosineCount)];
  std::call_once(t.integrated[size_t(j)], [&] {
    const float y = float(j) / (kRoughnessCount - 1);
    const float roughness = y * y;
    std::array<float, kCosineCount> scale{}, bias{};
    for (int i = 0; i < kCosineCount; ++i) {
      const float x = float(i) / (kCosineCount - 1);
      row[i] = integrate(x * x, roughness);
      scale[size_t(i)] = row[i].scale;
      bias[size_t(i)] = row[i].bias;
    }
    t.average[size_t(j)] = {averageOfPiecewiseLinear(scale.data()),
                            averageOfPiecewiseLinear(bias.data())};
  });
  *average = t.average[size_t(j)];
  return row;
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
  int j;
  gridPosition(std::sqrt(std::clamp(roughness, 0.0f, 1.0f)), kRoughnessCount, &j, &weight_);
  SpecularAlbedoTerms lowerAverage, upperAverage;
  lower_ = tableRow(j, &lowerAverage);
  upper_ = tableRow(j + 1, &upperAverage);
  average_ = lerp(lowerAverage, upperAverage, weight_);
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
