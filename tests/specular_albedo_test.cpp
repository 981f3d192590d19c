// The specular-albedo table compiled into the renderer (specular_albedo_table.inc): it is what
// the integration gives today, and that integration agrees with an independent Monte Carlo
// estimate of the GGX lobe's albedo and with Schlick's Fresnel in the smooth limit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "renderer/integrator/fresnel.h"
#include "renderer/integrator/microfacet.h"
#include "renderer/integrator/specular_albedo_integral.h"

namespace chorus::render {
namespace {

TEST(SpecularAlbedo, CompiledTableIsTheIntegral) {
  const SpecularAlbedoTable t = integrateSpecularAlbedoTable();
  for (int j = 0; j < kSpecularAlbedoRoughnesses; ++j) {
    const float y = float(j) / (kSpecularAlbedoRoughnesses - 1);
    const SpecularAlbedoRow row(y * y);
    // Lookups at the grid's nodes (up to the rounding of sqrt in the interpolation).
    EXPECT_NEAR(row.average().scale, t.average[size_t(j)].scale, 2e-6f) << j;
    EXPECT_NEAR(row.average().bias, t.average[size_t(j)].bias, 2e-6f) << j;
    for (int i = 0; i < kSpecularAlbedoCosines; ++i) {
      const float x = float(i) / (kSpecularAlbedoCosines - 1);
      const SpecularAlbedoTerms node = t.directional[size_t(j * kSpecularAlbedoCosines + i)];
      const SpecularAlbedoTerms looked = row.at(x * x);
      ASSERT_NEAR(looked.scale, node.scale, 2e-6f) << "regenerate specular_albedo_table.inc";
      ASSERT_NEAR(looked.bias, node.bias, 2e-6f) << "regenerate specular_albedo_table.inc";
    }
  }
}

// E = ∫ F D G / (4 μo μi) μi dωi by sampling half vectors with density D(h) h.z (Walter et al.
// 2007), not the table's visible normals: pdf(wi) = D h.z / (4 wo·h), so each sample weighs
// G (wo·h) / (μo h.z). F ≡ 1 gives scale + bias, F = (1 − wo·h)^5 gives bias.
SpecularAlbedoTerms monteCarlo(float mu, float roughness, int samples) {
  const GgxDistribution ggx = GgxDistribution::fromRoughness(roughness);
  const float alpha = roughness * roughness;
  const Vec3f wo{std::sqrt(1 - mu * mu), 0, mu};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  double e1 = 0, e5 = 0;
  for (int k = 0; k < samples; ++k) {
    const double u = uniform(rng), phi = 2 * kPi * uniform(rng);
    const double tan2 = alpha * alpha * u / (1 - u);
    const double cosH = 1 / std::sqrt(1 + tan2), sinH = std::sqrt(1 - cosH * cosH);
    const Vec3f h{float(sinH * std::cos(phi)), float(sinH * std::sin(phi)), float(cosH)};
    const float cosOH = dot(wo, h);
    if (cosOH <= 0) continue;
    const Vec3f wi = h * (2 * cosOH) - wo;
    if (wi.z <= 0) continue;
    const double weight = double(ggx.G(wo, wi)) * cosOH / (mu * cosH);
    e1 += weight;
    e5 += weight * schlickWeight(cosOH);
  }
  return {float((e1 - e5) / samples), float(e5 / samples)};
}

TEST(SpecularAlbedo, AgreesWithMonteCarloAndWithSchlickWhenSmooth) {
  for (const float roughness : {0.2f, 0.5f, 1.0f})
    for (const float mu : {0.15f, 0.5f, 0.95f}) {
      const SpecularAlbedoTerms table = specularAlbedo(mu, roughness);
      const SpecularAlbedoTerms mc = monteCarlo(mu, roughness, 200000);
      const float albedo = table.scale + table.bias;
      EXPECT_NEAR(albedo, mc.scale + mc.bias, 0.01f * std::max(albedo, 0.1f))
          << roughness << " " << mu;
      EXPECT_NEAR(table.bias, mc.bias, 0.002f) << roughness << " " << mu;
      EXPECT_LE(albedo, 1.0f + 1e-4f);
    }
  for (const float mu : {0.1f, 0.6f, 1.0f}) {
    const SpecularAlbedoTerms smooth = specularAlbedo(mu, 0.0f);
    EXPECT_NEAR(smooth.bias, schlickWeight(mu), 2e-3f) << mu;  // interpolated between nodes
    EXPECT_NEAR(smooth.scale + smooth.bias, 1.0f, 1e-6f) << mu;
  }
}

}  // namespace
}  // namespace chorus::render
