#include "renderer/integrator/specular_albedo_integral.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "renderer/integrator/fresnel.h"
#include "renderer/integrator/microfacet.h"

namespace chorus::render {
namespace {

constexpr int kQuadrature = 32;  // midpoint samples per axis of the VNDF sample square

// 2 ∫ e(μ) μ dμ = 4 ∫ e(x) x³ dx for e linear in x = sqrt(μ) between the table's samples,
// exactly.
float averageOfPiecewiseLinear(const float* e) {
  const double h = 1.0 / (kSpecularAlbedoCosines - 1);
  double sum = 0;
  for (int i = 0; i + 1 < kSpecularAlbedoCosines; ++i) {
    const double a = i * h, b = a + h;
    const double x3 = (std::pow(b, 4) - std::pow(a, 4)) / 4;                 // ∫ x³
    const double x3Offset = (std::pow(b, 5) - std::pow(a, 5)) / 5 - a * x3;  // ∫ (x − a) x³
    sum += e[i] * x3 + (e[i + 1] - e[i]) / h * x3Offset;
  }
  return float(4.0 * sum);
}

}  // namespace

// E1 = ∫ f cos with F ≡ 1, and E5 = the same with F = (1 − wo·h)^5, by sampling visible
// normals: with wi = reflect(wo, h) the estimator f cos / pdf is G2 / G1(wo).
SpecularAlbedoTerms integrateSpecularAlbedo(float cosTheta, float roughness) {
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

SpecularAlbedoTable integrateSpecularAlbedoTable() {
  SpecularAlbedoTable t;
  t.directional.resize(size_t(kSpecularAlbedoRoughnesses) * kSpecularAlbedoCosines);
  for (int j = 0; j < kSpecularAlbedoRoughnesses; ++j) {
    const float y = float(j) / (kSpecularAlbedoRoughnesses - 1);
    SpecularAlbedoTerms* row = &t.directional[size_t(j) * kSpecularAlbedoCosines];
    std::array<float, kSpecularAlbedoCosines> scale{}, bias{};
    for (int i = 0; i < kSpecularAlbedoCosines; ++i) {
      const float x = float(i) / (kSpecularAlbedoCosines - 1);
      row[i] = integrateSpecularAlbedo(x * x, y * y);
      scale[size_t(i)] = row[i].scale;
      bias[size_t(i)] = row[i].bias;
    }
    t.average.push_back(
        {averageOfPiecewiseLinear(scale.data()), averageOfPiecewiseLinear(bias.data())});
  }
  return t;
}

}  // namespace chorus::render
