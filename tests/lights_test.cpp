// Light sampling against analytic irradiance and against its own pdf functions: emissive
// triangles (form factor of a square emitter), punctual lights (inverse square, spot cone) and
// the environment map (orientation, pdf normalisation, importance-sampled integral).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "common/error.h"
#include "common/image/exr_io.h"
#include "renderer/integrator/environment_light.h"
#include "renderer/integrator/lights.h"
#include "renderer/scene/scene.h"
#include "tests/support/test_support.h"

namespace chorus::render {
namespace {

// A square emitter of side `side` at height h above the origin, facing down, radiance Le.
SceneDesc squareEmitterScene(float side, float h, Rgb Le, bool doubleSided = false) {
  SceneDesc desc;
  MaterialDesc m;
  m.emissive = Le;
  m.baseColor = Rgb(0.0f);
  m.doubleSided = doubleSided;
  desc.materials.push_back(m);
  MeshDesc mesh;
  const float s = side / 2;
  mesh.positions = {{-s, h, -s}, {s, h, -s}, {s, h, s}, {-s, h, s}};
  mesh.indices = {0, 1, 2, 0, 2, 3};  // counter-clockwise seen from below: faces −y
  desc.meshes.push_back(mesh);
  for (const Vec3f& p : mesh.positions) desc.bounds.extend(p);
  desc.bounds.extend({0, 0, 0});
  return desc;
}

// Form factor from a differential area to a parallel rectangle with one corner above it
// (sides a, b at distance c): (1/2π)[X/√(1+X²) atan(Y/√(1+X²)) + Y/√(1+Y²) atan(X/√(1+Y²))].
double cornerFormFactor(double a, double b, double c) {
  const double x = a / c, y = b / c;
  const double sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
  return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2 * M_PI);
}

TEST(Lights, AreaLightSamplingReproducesTheFormFactor) {
  const float side = 2.0f, h = 1.5f;
  const Scene scene = buildScene(squareEmitterScene(side, h, Rgb(3.0f)), EnvironmentDesc{});
  EXPECT_FALSE(scene.usesDefaultEnvironment());
  const LightSet lights(scene);
  ASSERT_EQ(lights.areaLightCount(), 2u);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int n = 200000;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const auto s = lights.sample({0, 0, 0}, u(rng), {u(rng), u(rng)});
    ASSERT_TRUE(s);
    sum += s->Li.r * std::max(0.0f, s->wi.y) / s->pdf;
  }
  const double expected = M_PI * 3.0 * 4 * cornerFormFactor(side / 2, side / 2, h);
  EXPECT_NEAR(sum / n / expected, 1.0, 0.01);
}

TEST(Lights, AreaLightPdfMatchesWhatARayHitFinds) {
  const Scene scene = buildScene(squareEmitterScene(2.0f, 1.0f, Rgb(1.0f)), EnvironmentDesc{});
  const LightSet lights(scene);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const Vec3f ref{0.3f, -0.5f, 0.2f};
  for (int i = 0; i < 100; ++i) {
    const auto s = lights.sample(ref, u(rng), {u(rng), u(rng)});
    ASSERT_TRUE(s);
    Hit hit;
    ASSERT_TRUE(scene.intersect({ref, s->wi}, &hit));
    const SurfaceInteraction si = scene.interaction(hit, s->wi);
    EXPECT_NEAR(lights.pdfAreaLight(ref, si) / s->pdf, 1.0f, 1e-3f);
    EXPECT_NEAR(length(si.position - s->pLight), 0.0f, 1e-5f);
  }
}

TEST(Lights, SingleSidedEmittersAreDarkBehind) {
  const Scene one = buildScene(squareEmitterScene(2.0f, 1.0f, Rgb(1.0f)), EnvironmentDesc{});
  const Scene two = buildScene(squareEmitterScene(2.0f, 1.0f, Rgb(1.0f), true), EnvironmentDesc{});
  const LightSet backOnly(one), both(two);
  // From above, the single-sided emitter (facing down) gives nothing.
  EXPECT_FALSE(backOnly.sample({0, 2, 0}, 0.3f, {0.5f, 0.5f}));
  ASSERT_TRUE(both.sample({0, 2, 0}, 0.3f, {0.5f, 0.5f}));
  EXPECT_GT(both.sample({0, 2, 0}, 0.3f, {0.5f, 0.5f})->Li.r, 0.0f);
}

TEST(Lights, PunctualLightsFollowInverseSquareAndSpotCone) {
  SceneDesc desc = squareEmitterScene(0.0f, 0.0f, Rgb(0.0f));
  desc.materials[0].emissive = Rgb(0.0f);
  PunctualLightDesc spot;
  spot.type = PunctualLightType::Spot;
  spot.position = {0, 4, 0};
  spot.direction = {0, -1, 0};
  spot.intensity = 32;
  spot.innerConeAngle = 0.1f;
  spot.outerConeAngle = 0.3f;
  desc.lights.push_back(spot);
  const Scene scene = buildScene(desc, EnvironmentDesc{});
  const LightSet lights(scene);
  const auto below = lights.sample({0, 0, 0}, 0.5f, {0.5f, 0.5f});
  ASSERT_TRUE(below);
  EXPECT_TRUE(below->isDelta);
  EXPECT_FLOAT_EQ(below->pdf, 1.0f);
  EXPECT_NEAR(below->Li.r, 32.0f / 16.0f, 1e-5f);
  EXPECT_NEAR(below->wi.y, 1.0f, 1e-6f);
  // Outside the outer cone: nothing.
  EXPECT_FALSE(lights.sample({4, 0, 0}, 0.5f, {0.5f, 0.5f}));
  // Between the cones: the smooth falloff, strictly between 0 and the full value.
  const float x = 4.0f * std::tan(0.2f);
  const auto edge = lights.sample({x, 0, 0}, 0.5f, {0.5f, 0.5f});
  ASSERT_TRUE(edge);
  const float full = 32.0f / (16.0f + x * x);
  EXPECT_GT(edge->Li.r, 0.05f * full);
  EXPECT_LT(edge->Li.r, 0.95f * full);
}

TEST(Lights, DirectionalLightIsADeltaFromItsDirection) {
  SceneDesc desc = squareEmitterScene(0.0f, 0.0f, Rgb(0.0f));
  PunctualLightDesc sun;
  sun.type = PunctualLightType::Directional;
  sun.direction = normalize(Vec3f{1, -2, 0});
  sun.intensity = 3.0f;
  sun.color = {1.0f, 0.5f, 0.25f};
  desc.lights.push_back(sun);
  const Scene scene = buildScene(desc, EnvironmentDesc{});
  const auto s = LightSet(scene).sample({5, 5, 5}, 0.7f, {0.1f, 0.9f});
  ASSERT_TRUE(s);
  EXPECT_TRUE(s->isDelta);
  EXPECT_TRUE(s->isInfinite);
  EXPECT_FLOAT_EQ(s->pdf, 1.0f);
  EXPECT_NEAR(s->wi.x, -sun.direction.x, 1e-6f);
  EXPECT_NEAR(s->wi.y, -sun.direction.y, 1e-6f);
  EXPECT_FLOAT_EQ(s->Li.r, 3.0f);
  EXPECT_FLOAT_EQ(s->Li.b, 0.75f);
}

Image oneBrightTexel(int w, int h, int bx, int by) {
  Image image(w, h, 3, 0.0f);
  for (int c = 0; c < 3; ++c) image(bx, by, c) = 100.0f;
  return image;
}

EnvironmentDesc mapEnvironment(Image image, float rotation = 0) {
  EnvironmentDesc e;
  e.kind = EnvironmentDesc::Kind::Map;
  e.map = std::make_shared<const Image>(std::move(image));
  e.rotationDegrees = rotation;
  return e;
}

TEST(EnvironmentLight, CentreOfTheMapFacesMinusZAndRotatesAboutY) {
  const EnvironmentLight env(mapEnvironment(oneBrightTexel(64, 32, 32, 16)));
  EXPECT_GT(env.Le({0, 0, -1}).r, 0.0f);
  EXPECT_EQ(env.Le({0, 0, 1}).r, 0.0f);
  EXPECT_EQ(env.Le({0, 1, 0}).r, 0.0f);
  // Column 48 (u = 0.75) is +x.
  const EnvironmentLight east(mapEnvironment(oneBrightTexel(64, 32, 48, 16)));
  EXPECT_GT(east.Le({1, 0, 0}).r, 0.0f);
  // Rotating the centre texel by 90° about +y moves it from −z to −x.
  const EnvironmentLight turned(mapEnvironment(oneBrightTexel(64, 32, 32, 16), 90));
  EXPECT_GT(turned.Le({-1, 0, 0}).r, 0.0f);
  EXPECT_EQ(turned.Le({0, 0, -1}).r, 0.0f);
  // Row 0 is straight up (every column of it meets at the pole).
  Image topRow(64, 32, 3, 0.0f);
  for (int x = 0; x < 64; ++x) topRow(x, 0, 1) = 1.0f;
  const EnvironmentLight sky(mapEnvironment(topRow));
  EXPECT_GT(sky.Le({0, 1, 0}).g, 0.0f);
  EXPECT_EQ(sky.Le({0, -1, 0}).g, 0.0f);
}

Image smoothMap(int w, int h) {
  Image image(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      image(x, y, 0) = 1.0f + 20.0f * float(x == 7 && y == 5) + float(y) / float(h);
      image(x, y, 1) = 0.5f + 0.25f * std::sin(float(x));
      image(x, y, 2) = 0.1f;
    }
  return image;
}

TEST(EnvironmentLight, PdfIntegratesToOneAndMatchesSamples) {
  const EnvironmentLight env(mapEnvironment(smoothMap(32, 16), 30));
  // ∫ pdf dω over a fine (θ, φ) grid.
  const int nt = 400, np = 800;
  double integral = 0;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      const double theta = (i + 0.5) * M_PI / nt, phi = (j + 0.5) * 2 * M_PI / np;
      const Vec3f d{float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                    float(std::sin(theta) * std::sin(phi))};
      integral += env.pdfSolidAngle(d) * std::sin(theta) * (M_PI / nt) * (2 * M_PI / np);
    }
  EXPECT_NEAR(integral, 1.0, 0.01);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 200; ++i) {
    const auto s = env.sample({u(rng), u(rng)});
    ASSERT_TRUE(s);
    EXPECT_NEAR(env.pdfSolidAngle(s->wi) / s->pdfSolidAngle, 1.0f, 2e-3f);
    EXPECT_EQ(env.Le(s->wi).r, s->Le.r);
    // The fused lookup of an escaping path gives the same two values, the pdf only when asked.
    const EnvironmentLight::Arrival a = env.arrival(s->wi, true);
    EXPECT_EQ(a.Le.r, s->Le.r);
    EXPECT_EQ(a.pdfSolidAngle, env.pdfSolidAngle(s->wi));
    EXPECT_EQ(env.arrival(s->wi, false).pdfSolidAngle, 0.0f);
  }
}

TEST(EnvironmentLight, ImportanceSampledIntegralMatchesTexelSum) {
  const int w = 32, h = 16;
  const Image map = smoothMap(w, h);
  const EnvironmentLight env(mapEnvironment(map));
  // Exact ∫ L_r dω of the piecewise-constant map: Σ L · Δφ (cos θ0 − cos θ1).
  double exact = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      exact +=
          map(x, y, 0) * (2 * M_PI / w) * (std::cos(y * M_PI / h) - std::cos((y + 1) * M_PI / h));
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double sum = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const auto s = env.sample({u(rng), u(rng)});
    ASSERT_TRUE(s);
    sum += s->Le.r / s->pdfSolidAngle;
  }
  EXPECT_NEAR(sum / n / exact, 1.0, 0.005);
}

TEST(EnvironmentLight, ReadsExrAndHdrFilesAndRejectsOthers) {
  test::TempDir dir;
  Image image(8, 4, 3, 0.5f);
  image(3, 1, 0) = -1.0f;  // negative texels become 0
  writeExr(dir / "env.exr", image);
  const EnvironmentDesc e = environmentFromFile(dir / "env.exr", 0.0f, 2.0f);
  ASSERT_EQ(e.kind, EnvironmentDesc::Kind::Map);
  EXPECT_EQ(e.map->width(), 8);
  EXPECT_EQ(e.map->at(3, 1, 0), 0.0f);
  const EnvironmentLight light(e);
  EXPECT_FLOAT_EQ(light.Le({0, -1, 0}).g, 1.0f);  // 0.5 × intensity 2
  std::ofstream(dir / "env.png") << "not an environment";
  EXPECT_THROW(environmentFromFile(dir / "env.png"), Error);
  EXPECT_THROW(environmentFromFile(dir / "missing.hdr"), Error);
  std::ofstream(dir / "bad.hdr") << "#?RADIANCE\ngarbage";
  EXPECT_THROW(environmentFromFile(dir / "bad.hdr"), Error);
}

TEST(EnvironmentLight, ConstantIsUniform) {
  const EnvironmentLight env(EnvironmentDesc::constant(Rgb(2.0f)));
  EXPECT_FLOAT_EQ(env.pdfSolidAngle({0, 1, 0}), 1.0f / (4.0f * kPi));
  EXPECT_FLOAT_EQ(env.Le({0.6f, 0, 0.8f}).g, 2.0f);
  EXPECT_FALSE(EnvironmentLight(EnvironmentDesc::constant(Rgb(0.0f))).emits());
}

}  // namespace
}  // namespace chorus::render
