// The glTF reference BSDF: χ² of sample() against the numerically integrated pdf() (pbrt's
// bsdfs_test, Mitsuba's chi2.py), sample/f/pdf consistency, reciprocity, energy conservation,
// the exact-Lambertian limit, smooth-interface physics and robustness on degenerate input.
#include "renderer/integrator/bsdf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "renderer/integrator/fresnel.h"
#include "renderer/sampling/sampler.h"
#include "tests/support/chi2.h"

namespace chorus::render {
namespace {

Vec3f direction(float cosTheta, float phi) {
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}

float uniform(std::mt19937& rng) {
  return std::uniform_real_distribution<float>(0.0f, 1.0f)(rng);
}

Vec3f randomDirection(std::mt19937& rng) {
  return direction(2.0f * uniform(rng) - 1.0f, 2.0f * kPi * uniform(rng));
}

struct NamedMaterial {
  std::string name;
  MaterialPoint material;
};

MaterialPoint dielectric(Rgb base, float roughness, float specular = 1.0f) {
  MaterialPoint m;
  m.baseColor = base;
  m.metallic = 0;
  m.roughness = roughness;
  m.specular = specular;
  return m;
}
MaterialPoint metal(Rgb base, float roughness) {
  MaterialPoint m;
  m.baseColor = base;
  m.metallic = 1;
  m.roughness = roughness;
  return m;
}
MaterialPoint glass(Rgb base, float roughness, bool thinWalled, float ior = 1.5f) {
  MaterialPoint m = dielectric(base, roughness);
  m.transmission = 1;
  m.thinWalled = thinWalled;
  m.ior = ior;
  return m;
}

std::vector<NamedMaterial> chi2Materials() {
  std::vector<NamedMaterial> list;
  list.push_back({"lambert (specular 0)", dielectric({0.7f, 0.5f, 0.3f}, 0.5f, 0.0f)});
  list.push_back({"plastic r0.5", dielectric({0.6f, 0.3f, 0.2f}, 0.5f)});
  MaterialPoint tinted = dielectric({0.2f, 0.4f, 0.8f}, 0.3f);
  tinted.specularColor = {1.0f, 0.5f, 0.2f};
  tinted.ior = 1.8f;
  list.push_back({"plastic r0.3 tinted ior1.8", tinted});
  list.push_back({"plastic smooth", dielectric({0.5f, 0.5f, 0.5f}, 0.0f)});
  list.push_back({"metal r0.3 gold", metal({1.0f, 0.78f, 0.34f}, 0.3f)});
  list.push_back({"metal r0.9", metal({0.9f, 0.9f, 0.9f}, 0.9f)});
  MaterialPoint mixed = dielectric({0.8f, 0.2f, 0.2f}, 0.4f);
  mixed.metallic = 0.5f;
  list.push_back({"mixed m0.5 r0.4", mixed});
  list.push_back({"glass solid r0.3", glass(Rgb(1.0f), 0.3f, false)});
  list.push_back(
      {"glass solid r0.6 tinted ior1.33", glass({0.9f, 0.7f, 0.5f}, 0.6f, false, 1.33f)});
  list.push_back({"glass thin r0.4", glass(Rgb(1.0f), 0.4f, true)});
  MaterialPoint half = glass({0.8f, 0.8f, 0.6f}, 0.5f, false);
  half.transmission = 0.5f;
  half.metallic = 0.2f;
  list.push_back({"half transmissive m0.2 r0.5", half});
  MaterialPoint weakSpecular = glass(Rgb(1.0f), 0.35f, false);
  weakSpecular.specular = 0.5f;
  list.push_back({"glass solid r0.35 specular0.5", weakSpecular});
  return list;
}

struct Chi2Case {
  std::string name;
  MaterialPoint material;
  Vec3f wo;
};

std::vector<Chi2Case> chi2Cases() {
  std::vector<Chi2Case> cases;
  for (const NamedMaterial& m : chi2Materials()) {
    std::vector<float> cosines{0.95f, 0.6f, 0.15f};
    if (m.material.transmission > 0 && !m.material.thinWalled)
      cosines.insert(cosines.end(), {-0.9f, -0.5f, -0.15f});
    for (float c : cosines) {
      char name[160];
      std::snprintf(name, sizeof name, "%s, cos(wo) %.2f", m.name.c_str(), c);
      cases.push_back({name, m.material, direction(c, 0.3f)});
    }
  }
  return cases;
}

constexpr int kThetaBins = 32, kPhiBins = 64;  // equal-area cells: uniform in cos θ and φ
constexpr int kSubdivisions = 12;              // midpoint rule per cell axis for ∫ pdf

int cellOf(Vec3f w) {
  const int zi = std::clamp(int((w.z + 1.0f) * 0.5f * kThetaBins), 0, kThetaBins - 1);
  float phi = std::atan2(w.y, w.x);
  if (phi < 0) phi += 2.0f * kPi;
  const int pi = std::clamp(int(phi / (2.0f * kPi) * kPhiBins), 0, kPhiBins - 1);
  return zi * kPhiBins + pi;
}

// Expected counts: n × ∫_cell pdf dω, with dω = dz dφ.
std::vector<double> expectedCounts(const Bsdf& bsdf, Vec3f wo, int n) {
  std::vector<double> expected(kThetaBins * kPhiBins, 0.0);
  const double dz = 2.0 / kThetaBins / kSubdivisions;
  const double dphi = 2.0 * M_PI / kPhiBins / kSubdivisions;
  for (int zi = 0; zi < kThetaBins; ++zi)
    for (int pi = 0; pi < kPhiBins; ++pi) {
      double integral = 0;
      for (int a = 0; a < kSubdivisions; ++a)
        for (int b = 0; b < kSubdivisions; ++b) {
          const double z = -1.0 + (zi * kSubdivisions + a + 0.5) * dz;
          const double phi = (pi * kSubdivisions + b + 0.5) * dphi;
          integral += bsdf.pdf(wo, direction(float(z), float(phi)));
        }
      expected[size_t(zi * kPhiBins + pi)] = n * integral * dz * dphi;
    }
  return expected;
}

TEST(Bsdf, SamplingMatchesPdfChi2) {
  const std::vector<Chi2Case> cases = chi2Cases();
  const double significance = test::sidakSignificance(0.01, int(cases.size()));
  const int n = 200000;
  std::mt19937 rng(12345);
  double minP = 1;
  for (const Chi2Case& c : cases) {
    const Bsdf bsdf(c.material);
    std::vector<double> observed(kThetaBins * kPhiBins, 0.0);
    for (int i = 0; i < n; ++i) {
      const float uLobe = uniform(rng);
      const Vec2f u{uniform(rng), uniform(rng)};
      const auto s = bsdf.sample(c.wo, uLobe, u);
      if (!s || s->isDelta) continue;
      observed[size_t(cellOf(s->wi))] += 1;
    }
    const std::vector<double> expected = expectedCounts(bsdf, c.wo, n);
    const test::Chi2Result result = test::chi2Test(observed, expected);
    std::printf("chi2 %-52s chi2 %8.1f dof %4d p %.4f\n", c.name.c_str(), result.chi2, result.dof,
                result.pValue);
    EXPECT_TRUE(result.problem.empty()) << c.name << ": " << result.problem;
    EXPECT_GT(result.pValue, significance)
        << c.name << ": chi2 " << result.chi2 << ", dof " << result.dof << "\n"
        << test::formatChi2Tables(observed, expected, kThetaBins, kPhiBins);
    minP = std::min(minP, result.pValue);
  }
  std::printf("chi2: %zu cases, smallest p %.4f, Sidak threshold %.2e\n", cases.size(), minP,
              significance);
}

TEST(Bsdf, SampleAgreesWithFAndPdf) {
  std::mt19937 rng(7);
  for (const NamedMaterial& m : chi2Materials()) {
    const Bsdf bsdf(m.material);
    int checked = 0;
    for (int i = 0; i < 20000; ++i) {
      const Vec3f wo = randomDirection(rng);
      const auto s = bsdf.sample(wo, uniform(rng), {uniform(rng), uniform(rng)});
      if (!s) continue;
      ASSERT_TRUE(s->f.isFinite() && std::isfinite(s->pdf) && s->pdf > 0) << m.name;
      ASSERT_NEAR(length(s->wi), 1.0f, 1e-4f) << m.name;
      EXPECT_EQ(s->isTransmission, s->wi.z * wo.z < 0) << m.name;
      if (s->isDelta) continue;
      const Rgb f = bsdf.f(wo, s->wi);
      const float pdf = bsdf.pdf(wo, s->wi);
      for (int ch = 0; ch < 3; ++ch)
        ASSERT_NEAR(s->f[ch], f[ch], 1e-4f * std::max(1.0f, f[ch])) << m.name << " channel " << ch;
      ASSERT_NEAR(s->pdf, pdf, 1e-4f * std::max(1.0f, pdf)) << m.name;
      // The path weight f cos / pdf, as the integrator uses it.
      const float weightSample = s->f.average() * std::abs(s->wi.z) / s->pdf;
      const float weightRecomputed = f.average() * std::abs(s->wi.z) / pdf;
      ASSERT_NEAR(weightSample, weightRecomputed, 1e-4f * std::max(1.0f, weightRecomputed));
      ++checked;
    }
    EXPECT_GT(checked, 1000) << m.name;
  }
}

TEST(Bsdf, ReflectionIsReciprocal) {
  std::mt19937 rng(8);
  for (const NamedMaterial& m : chi2Materials()) {
    const Bsdf bsdf(m.material);
    for (int i = 0; i < 5000; ++i) {
      Vec3f wo = randomDirection(rng), wi = randomDirection(rng);
      // Same side of the surface (outside; for solids also inside).
      if (wi.z * wo.z < 0) wi.z = -wi.z;
      if (!(m.material.transmission > 0 && !m.material.thinWalled) && wo.z < 0) {
        wo.z = -wo.z;
        wi.z = -wi.z;
      }
      const Rgb a = bsdf.f(wo, wi), b = bsdf.f(wi, wo);
      for (int ch = 0; ch < 3; ++ch)
        ASSERT_NEAR(a[ch], b[ch], 2e-4f * std::max(1.0f, a[ch]))
            << m.name << " wo (" << wo.x << "," << wo.y << "," << wo.z << ") wi (" << wi.x << ","
            << wi.y << "," << wi.z << ")";
    }
  }
}

// Generalised reciprocity of refraction: f(wo, wi) / n_o² = f(wi, wo) / n_i².
TEST(Bsdf, TransmissionObeysGeneralisedReciprocity) {
  std::mt19937 rng(9);
  for (const NamedMaterial& m : chi2Materials()) {
    if (m.material.transmission == 0) continue;
    const Bsdf bsdf(m.material);
    const bool solid = !m.material.thinWalled;
    int nonZero = 0;
    for (int i = 0; i < 5000; ++i) {
      const Vec3f wo = randomDirection(rng);
      Vec3f wi = randomDirection(rng);
      if (wi.z * wo.z > 0) wi.z = -wi.z;
      const float nO = solid && wo.z < 0 ? m.material.ior : 1.0f;
      const float nI = solid && wi.z < 0 ? m.material.ior : 1.0f;
      const Rgb a = bsdf.f(wo, wi) / (nO * nO), b = bsdf.f(wi, wo) / (nI * nI);
      for (int ch = 0; ch < 3; ++ch)
        ASSERT_NEAR(a[ch], b[ch], 2e-4f * std::max(1.0f, a[ch])) << m.name;
      nonZero += a.maxComponent() > 0;
    }
    EXPECT_GT(nonZero, 100) << m.name;
  }
}

// Directional albedo ∫ f cos dωi by importance sampling with sample() and scrambled Sobol
// points, counting energy: refracted radiance is scaled back by η² (flux, not radiance).
struct Albedo {
  Rgb mean;
  float standardError = 0;  // of the channel average
};
Albedo directionalAlbedo(const MaterialPoint& material, Vec3f wo, int n, int pixel) {
  const Bsdf bsdf(material);
  Sampler sampler(77);
  Rgb sum;
  double sumSq = 0, sumAvg = 0;
  for (int i = 0; i < n; ++i) {
    sampler.startPixelSample(pixel, 0, uint32_t(i), 0);
    const float uLobe = sampler.get1D();
    const Vec2f u = sampler.get2D();
    const auto s = bsdf.sample(wo, uLobe, u);
    if (!s) continue;
    Rgb weight = s->f * (std::abs(s->wi.z) / s->pdf);
    if (s->isTransmission && !material.thinWalled) {
      const float eta = wo.z > 0 ? material.ior : 1.0f / material.ior;
      weight *= eta * eta;
    }
    sum += weight;
    sumAvg += weight.average();
    sumSq += double(weight.average()) * weight.average();
  }
  const double mean = sumAvg / n;
  const double variance = std::max(0.0, sumSq / n - mean * mean);
  return {sum / float(n), float(std::sqrt(variance / n))};
}

TEST(Bsdf, EnergyIsConservedForEveryParameterCombination) {
  int combinations = 0;
  float maxAlbedo = 0;
  std::string worst;
  for (float roughness : {0.0f, 0.05f, 0.2f, 0.5f, 1.0f})
    for (float metallic : {0.0f, 0.5f, 1.0f})
      for (float transmission : {0.0f, 0.5f, 1.0f})
        for (float specular : {0.0f, 0.5f, 1.0f})
          for (bool thin : {false, true})
            for (float cosTheta : {1.0f, 0.5f, 0.1f, 0.01f, -0.6f, -0.05f}) {
              if (cosTheta < 0 && (thin || transmission == 0)) continue;
              MaterialPoint m = dielectric(Rgb(1.0f), roughness, specular);
              m.metallic = metallic;
              m.transmission = transmission;
              m.thinWalled = thin;
              const Albedo a = directionalAlbedo(m, direction(cosTheta, 1.0f), 4096, combinations);
              ++combinations;
              char text[200];
              std::snprintf(text, sizeof text,
                            "roughness %.2f metallic %.1f transmission %.1f specular %.1f %s "
                            "cos %.2f: albedo %.5f ± %.5f",
                            roughness, metallic, transmission, specular, thin ? "thin" : "solid",
                            cosTheta, a.mean.average(), a.standardError);
              // The layer-albedo table is accurate to ~1e-3; allow that plus 4 standard errors.
              EXPECT_LE(a.mean.maxComponent(), 1.0f + 2e-3f + 4 * a.standardError) << text;
              EXPECT_GE(a.mean.maxComponent(), 0.0f) << text;
              if (a.mean.maxComponent() > maxAlbedo)
                maxAlbedo = a.mean.maxComponent(), worst = text;
            }
  std::printf("energy: %d combinations, largest albedo: %s\n", combinations, worst.c_str());
}

TEST(Bsdf, WhiteFurnaceCasesReflectEverything) {
  struct Case {
    std::string name;
    MaterialPoint material;
    float tolerance;
  };
  const std::vector<Case> cases{
      {"white Lambertian", dielectric(Rgb(1.0f), 0.5f, 0.0f), 1e-5f},
      {"white smooth metal", metal(Rgb(1.0f), 0.0f), 1e-5f},
      {"smooth glass sphere (solid)", glass(Rgb(1.0f), 0.0f, false), 1e-5f},
      {"smooth thin glass", glass(Rgb(1.0f), 0.0f, true), 1e-5f},
      {"smooth dielectric over white diffuse", dielectric(Rgb(1.0f), 0.0f), 2e-3f},
      {"rough dielectric over white diffuse", dielectric(Rgb(1.0f), 0.5f), 5e-3f},
      {"very rough dielectric over white diffuse", dielectric(Rgb(1.0f), 1.0f), 5e-3f},
  };
  for (const Case& c : cases)
    for (float cosTheta : {1.0f, 0.7f, 0.3f, 0.05f, -0.9f, -0.4f}) {
      if (cosTheta < 0 && (c.material.transmission == 0 || c.material.thinWalled)) continue;
      const Albedo a = directionalAlbedo(c.material, direction(cosTheta, 0.4f), 16384, 1);
      std::printf("furnace %-40s cos %5.2f: albedo %.6f\n", c.name.c_str(), cosTheta,
                  a.mean.average());
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(a.mean[ch], 1.0f, c.tolerance) << c.name << " cos " << cosTheta;
    }
}

// The same energy balance without sample(): ∫ f cos by quadrature over the hemisphere.
TEST(Bsdf, QuadratureAlbedoOfLayeredDielectricIsOne) {
  for (float roughness : {0.3f, 0.7f})
    for (float cosTheta : {0.9f, 0.4f}) {
      const Bsdf bsdf(dielectric(Rgb(1.0f), roughness));
      const Vec3f wo = direction(cosTheta, 0.0f);
      const int nz = 2000, nphi = 400;
      double sum = 0;
      for (int a = 0; a < nz; ++a)
        for (int b = 0; b < nphi; ++b) {
          const float z = (a + 0.5f) / nz;
          const Vec3f wi = direction(z, 2.0f * kPi * (b + 0.5f) / nphi);
          sum += double(bsdf.f(wo, wi).average()) * z;
        }
      const double albedo = sum * (1.0 / nz) * (2.0 * M_PI / nphi);
      EXPECT_NEAR(albedo, 1.0, 5e-3) << "roughness " << roughness << " cos " << cosTheta;
    }
}

TEST(Bsdf, SpecularFactorZeroIsExactlyLambertian) {
  std::mt19937 rng(10);
  for (int i = 0; i < 2000; ++i) {
    MaterialPoint m = dielectric({uniform(rng), uniform(rng), uniform(rng)}, uniform(rng), 0.0f);
    m.ior = 1.0f + 2.0f * uniform(rng);
    m.specularColor = {uniform(rng), uniform(rng), uniform(rng)};
    const Bsdf bsdf(m);
    Vec3f wo = randomDirection(rng), wi = randomDirection(rng);
    wo.z = std::abs(wo.z);
    wi.z = std::abs(wi.z);
    const Rgb f = bsdf.f(wo, wi);
    const Rgb lambert = m.baseColor * kInvPi;
    EXPECT_EQ(f.r, lambert.r);
    EXPECT_EQ(f.g, lambert.g);
    EXPECT_EQ(f.b, lambert.b);
    EXPECT_FLOAT_EQ(bsdf.pdf(wo, wi), wi.z * kInvPi);
    const auto s = bsdf.sample(wo, uniform(rng), {uniform(rng), uniform(rng)});
    ASSERT_TRUE(s);
    EXPECT_FALSE(s->isDelta);
    EXPECT_FLOAT_EQ(s->pdf, s->wi.z * kInvPi);
    EXPECT_EQ(bsdf.albedo().r, m.baseColor.r);
    EXPECT_EQ(bsdf.albedo().b, m.baseColor.b);
  }
}

TEST(Bsdf, SmoothInterfaceFollowsSnellAndFresnel) {
  const float ior = 1.5f;
  const Bsdf solid(glass(Rgb(1.0f), 0.0f, false, ior));
  const Bsdf thin(glass(Rgb(1.0f), 0.0f, true, ior));
  EXPECT_TRUE(solid.isPurelySpecular());
  EXPECT_TRUE(solid.hasTransmission());
  for (float cosTheta : {0.9f, 0.5f, 0.2f, -0.95f, -0.8f, -0.5f}) {
    const Vec3f wo = direction(cosTheta, 0.7f);
    int reflected = 0, refracted = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const auto s = solid.sample(wo, (i + 0.5f) / n, {0.3f, 0.6f});
      ASSERT_TRUE(s);
      ASSERT_TRUE(s->isDelta);
      if (!s->isTransmission) {
        ++reflected;
        EXPECT_NEAR(s->wi.x, -wo.x, 1e-6f);
        EXPECT_NEAR(s->wi.y, -wo.y, 1e-6f);
        EXPECT_NEAR(s->wi.z, wo.z, 1e-6f);
        continue;
      }
      ++refracted;
      // Snell: n_o sin θo = n_i sin θi, in the plane of incidence, on the other side.
      const float nO = wo.z > 0 ? 1.0f : ior, nI = wo.z > 0 ? ior : 1.0f;
      const float sinO = std::sqrt(1 - wo.z * wo.z), sinI = std::sqrt(1 - s->wi.z * s->wi.z);
      EXPECT_NEAR(nO * sinO, nI * sinI, 1e-5f);
      EXPECT_LT(s->wi.x * wo.x, 0.0f);
      EXPECT_LT(s->wi.z * wo.z, 0.0f);
      // The transmitted radiance carries (1 − F) / η².
      const float eta = nI / nO;
      const float cosOuter = wo.z > 0 ? wo.z : std::abs(s->wi.z);
      const float fresnel = f0FromIor(ior) + (1 - f0FromIor(ior)) * std::pow(1 - cosOuter, 5.0f);
      EXPECT_NEAR(s->f.g * std::abs(s->wi.z), (1 - fresnel) / (eta * eta), 1e-5f);
    }
    // Reflection is chosen with probability F (Schlick at the outer cosine; 1 beyond the
    // critical angle, sin θ > 1/1.5 from inside).
    const float sinO = std::sqrt(1 - cosTheta * cosTheta);
    float expectedF = 1.0f;
    if (cosTheta > 0) {
      expectedF = f0FromIor(ior) + (1 - f0FromIor(ior)) * std::pow(1 - cosTheta, 5.0f);
    } else if (sinO * ior < 1) {
      const float cosOuter = std::sqrt(1 - sinO * sinO * ior * ior);
      expectedF = f0FromIor(ior) + (1 - f0FromIor(ior)) * std::pow(1 - cosOuter, 5.0f);
    }
    EXPECT_NEAR(float(reflected) / n, expectedF, 2e-3f) << "cos " << cosTheta;
    EXPECT_EQ(reflected + refracted, n);
  }
  // Thin-walled: straight through, no bending.
  const Vec3f wo = direction(0.4f, 1.1f);
  const auto s = thin.sample(wo, 0.999f, {0.5f, 0.5f});
  ASSERT_TRUE(s && s->isTransmission);
  EXPECT_NEAR(s->wi.x, -wo.x, 1e-6f);
  EXPECT_NEAR(s->wi.y, -wo.y, 1e-6f);
  EXPECT_NEAR(s->wi.z, -wo.z, 1e-6f);
}

TEST(Bsdf, SurfaceQueries) {
  EXPECT_TRUE(Bsdf(metal(Rgb(0.9f), 0.0f)).isPurelySpecular());
  EXPECT_FALSE(Bsdf(metal(Rgb(0.9f), 0.2f)).isPurelySpecular());
  EXPECT_FALSE(Bsdf(dielectric(Rgb(0.5f), 0.0f)).isPurelySpecular());  // diffuse base
  EXPECT_TRUE(Bsdf(dielectric(Rgb(0.0f), 0.0f)).isPurelySpecular());   // black: coating only
  EXPECT_FALSE(Bsdf(dielectric(Rgb(0.5f), 0.3f)).hasTransmission());
  EXPECT_TRUE(Bsdf(glass(Rgb(1.0f), 0.3f, true)).hasTransmission());
  MaterialPoint metallicGlass = glass(Rgb(1.0f), 0.3f, false);
  metallicGlass.metallic = 1;
  EXPECT_FALSE(Bsdf(metallicGlass).hasTransmission());
  // Albedo: baseColor for metals and for a diffuse without specular layer.
  const Rgb gold{1.0f, 0.78f, 0.34f};
  EXPECT_FLOAT_EQ(Bsdf(metal(gold, 0.4f)).albedo().b, gold.b);
  const Rgb plastic = Bsdf(dielectric({0.5f, 0.2f, 0.1f}, 0.4f)).albedo();
  EXPECT_GT(plastic.r, 0.5f);  // the coating adds a little white reflectance
  EXPECT_LT(plastic.r, 0.6f);
}

TEST(Bsdf, DegenerateDirectionsGiveFiniteValues) {
  std::vector<MaterialPoint> materials;
  for (const NamedMaterial& m : chi2Materials()) materials.push_back(m.material);
  for (float roughness : {0.0f, 1e-3f, 2e-3f, 1.0f}) {
    materials.push_back(glass(Rgb(1.0f), roughness, false, 1.0f));
    materials.push_back(glass(Rgb(1.0f), roughness, false, 1.0001f));
    materials.push_back(glass(Rgb(0.5f), roughness, true, 10.0f));
    materials.push_back(metal(Rgb(0.0f), roughness));
    materials.push_back(dielectric(Rgb(1.0f), roughness));
  }
  MaterialPoint nan = dielectric(Rgb(NAN), NAN);
  nan.ior = NAN;
  nan.metallic = NAN;
  materials.push_back(nan);

  std::vector<Vec3f> directions{{0, 0, 1},
                                {0, 0, -1},
                                {1, 0, 0},
                                {0, 1, 0},
                                direction(1e-7f, 0.2f),
                                direction(-1e-7f, 0.2f),
                                direction(1e-30f, 2.0f),
                                direction(0.9999999f, 1.0f),
                                direction(-0.9999999f, 1.0f),
                                {1, 0, 1e-20f}};
  const std::vector<float> uValues{0.0f, 0x1.fffffep-1f, 0.5f, 1e-20f};
  for (const MaterialPoint& m : materials) {
    const Bsdf bsdf(m);
    EXPECT_TRUE(bsdf.albedo().isFinite());
    for (const Vec3f& wo : directions) {
      for (const Vec3f& wiBase : directions)
        for (const Vec3f& wi : {wiBase, -wiBase, -wo, wo, Vec3f(-wo.x, -wo.y, wo.z)}) {
          const Rgb f = bsdf.f(wo, wi);
          const float pdf = bsdf.pdf(wo, wi);
          ASSERT_TRUE(f.isFinite() && f.r >= 0 && f.g >= 0 && f.b >= 0)
              << "f " << f.r << " " << f.g << " " << f.b << " roughness " << m.roughness << " ior "
              << m.ior << " wo " << wo.x << " " << wo.y << " " << wo.z << " wi " << wi.x << " "
              << wi.y << " " << wi.z;
          ASSERT_TRUE(std::isfinite(pdf) && pdf >= 0);
        }
      for (float uLobe : uValues)
        for (float ux : uValues)
          for (float uy : uValues) {
            const auto s = bsdf.sample(wo, uLobe, {ux, uy});
            if (!s) continue;
            ASSERT_TRUE(s->f.isFinite() && std::isfinite(s->pdf) && s->pdf > 0);
            ASSERT_TRUE(isFinite(s->wi));
            ASSERT_NEAR(length(s->wi), 1.0f, 1e-3f);
            ASSERT_TRUE(std::isfinite(s->f.average() * std::abs(s->wi.z) / s->pdf));
          }
    }
  }
}

}  // namespace
}  // namespace chorus::render
