// Light transport against analytic answers: white furnaces (Lambertian and glass spheres in a
// uniform environment, an emissive enclosure's infinite series), a Lambertian sphere under an
// environment map (quadrature over its texels), a Lambertian plane under a point light
// (E·ρ/π with inverse-square falloff) and under a square area light (form factor), and a thin
// lens's blur of an emitter's edge (the fraction of the lens disk that sees it).
#include <gtest/gtest.h>

#include <stb_image_write.h>

#include <cmath>
#include <numeric>

#include "common/error.h"
#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tests/support/gltf_builder.h"
#include "tests/support/test_support.h"

namespace chorus::render {
namespace {

using nlohmann::json;
using test::GltfBuilder;

struct PixelCheck {
  double meanRelativeError = 0;  // |Σ value − Σ expected| / Σ expected over checked pixels
  int outliers = 0;              // pixels outside max(tolerance, 5σ)
  int checked = 0;
};

// Compares each pixel's colour (channel c) to expected(x, y) (pixels with expected < 0 are
// skipped), allowing the larger of a relative tolerance and five standard errors.
template <typename Expected>
PixelCheck checkPixels(const SubBuffer& full, Expected expected, double relativeTolerance,
                       int channel = 0) {
  PixelCheck c;
  double sum = 0, sumExpected = 0;
  for (int y = 0; y < full.height(); ++y)
    for (int x = 0; x < full.width(); ++x) {
      const double e = expected(x, y);
      if (e < 0) continue;
      const double v = full.color.mean.at(x, y, channel);
      const double sigma = std::sqrt(full.color.varianceOfMean.at(x, y, channel));
      if (std::abs(v - e) > std::max(relativeTolerance * e, 5 * sigma)) {
        if (c.outliers < 5)
          ADD_FAILURE() << "pixel " << x << "," << y << ": " << v << " vs " << e << " ± " << sigma;
        ++c.outliers;
      }
      sum += v;
      sumExpected += e;
      ++c.checked;
    }
  c.meanRelativeError = std::abs(sum - sumExpected) / sumExpected;
  return c;
}

RenderResult renderGltf(const GltfBuilder& b, const EnvironmentDesc& env,
                        const RenderOptions& options) {
  test::TempDir dir;
  b.writeGltf(dir / "scene.gltf");
  const Scene scene = buildScene(loadGltf(dir / "scene.gltf"), env);
  return render(scene, options);
}

RenderOptions options(int size, int spp, int maxDepth = 8) {
  RenderOptions o;
  o.width = o.height = size;
  o.spp = spp;
  o.maxDepth = maxDepth;
  o.seed = 1;
  return o;
}

const float kS = std::sqrt(0.5f);

// A camera at (0, 0, 3) looking down −z at a unit sphere.
void addSphereCamera(GltfBuilder& b) {
  const int cam =
      b.addCamera({{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.01}}}});
  b.addNode({{"camera", cam}, {"translation", {0, 0, 3}}});
}

TEST(WhiteFurnace, LambertianAlbedoOneSphereIsInvisible) {
  GltfBuilder b;
  b.addSphere({0, 0, 0}, 1.0f, b.addMaterial(test::lambertianMaterial(1, 1, 1)));
  addSphereCamera(b);
  const RenderResult r = renderGltf(b, EnvironmentDesc::constant(Rgb(1.0f)), options(16, 256, 64));
  const PixelCheck c = checkPixels(
      r.buffers.part(BufferPart::Full), [](int, int) { return 1.0; }, 0.01);
  EXPECT_EQ(c.outliers, 0);
  EXPECT_LT(c.meanRelativeError, 0.005);
  EXPECT_EQ(r.stats.nanSamplesDropped, 0u);
}

TEST(WhiteFurnace, SmoothGlassSphereIsInvisible) {
  GltfBuilder b;
  json glass = {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}},
                {"extensions",
                 {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                  {"KHR_materials_volume", {{"thicknessFactor", 1.0}}}}}};
  b.addSphere({0, 0, 0}, 1.0f, b.addMaterial(glass));
  addSphereCamera(b);
  const RenderResult r = renderGltf(b, EnvironmentDesc::constant(Rgb(1.0f)), options(16, 64, 64));
  const PixelCheck c = checkPixels(
      r.buffers.part(BufferPart::Full), [](int, int) { return 1.0; }, 0.01);
  EXPECT_EQ(c.outliers, 0);
  EXPECT_LT(c.meanRelativeError, 0.005);
}

TEST(WhiteFurnace, LambertianAlbedoHalfSphereReflectsHalf) {
  GltfBuilder b;
  b.addSphere({0, 0, 0}, 1.0f, b.addMaterial(test::lambertianMaterial(0.5f, 0.5f, 0.5f)));
  addSphereCamera(b);
  const RenderResult r = renderGltf(b, EnvironmentDesc::constant(Rgb(1.0f)), options(16, 256, 64));
  // A convex object reflects the environment once: L = ρ · 1 on the sphere, 1 around it.
  // Pixels are classified by their corner rays against the sphere (with a margin for the
  // tessellation); pixels on the silhouette are skipped.
  const auto hitsSphere = [](float px, float py, float radius) {
    const float t = std::tan(0.4f);
    const Vec3f d = normalize({(2 * px / 16 - 1) * t, (1 - 2 * py / 16) * t, -1});
    const Vec3f o{0, 0, 3};
    const float bq = dot(o, d), cq = dot(o, o) - radius * radius;
    return bq * bq - cq >= 0;
  };
  const PixelCheck c = checkPixels(
      r.buffers.part(BufferPart::Full),
      [&](int x, int y) {
        int inside = 0, outside = 0;
        for (int corner = 0; corner < 4; ++corner) {
          const float px = float(x + (corner & 1)), py = float(y + (corner >> 1));
          inside += hitsSphere(px, py, 0.99f);
          outside += !hitsSphere(px, py, 1.01f);
        }
        return inside == 4 ? 0.5 : outside == 4 ? 1.0 : -1.0;
      },
      0.01);
  EXPECT_GT(c.checked, 150);
  EXPECT_EQ(c.outliers, 0);
  EXPECT_LT(c.meanRelativeError, 0.005);
}

// Inside a closed Lambertian enclosure of albedo ρ emitting Le everywhere, L = Le Σ ρᵏ =
// Le / (1 − ρ) whatever its shape: with ρ = 0.5, Le = 1 that is 2.
TEST(WhiteFurnace, EmissiveEnclosureSumsTheInfiniteSeries) {
  GltfBuilder b;
  json wall = test::lambertianMaterial(0.5f, 0.5f, 0.5f);
  wall["emissiveFactor"] = {1, 1, 1};
  wall["doubleSided"] = true;
  const int m = b.addMaterial(wall);
  std::vector<Vec3f> p;
  for (int i = 0; i < 8; ++i)
    p.push_back({i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f});
  b.addTriangleMesh(p, {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                        2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5},
                    m);
  const int cam =
      b.addCamera({{"type", "perspective"}, {"perspective", {{"yfov", 1.2}, {"znear", 0.01}}}});
  b.addNode({{"camera", cam}, {"translation", {0.1, 0.2, 0.3}}});
  const RenderResult r = renderGltf(b, EnvironmentDesc{}, options(8, 1024, 200));
  const PixelCheck c = checkPixels(
      r.buffers.part(BufferPart::Full), [](int, int) { return 2.0; }, 0.02);
  EXPECT_EQ(c.outliers, 0);
  EXPECT_LT(c.meanRelativeError, 0.01);
}

// An orthographic camera at height `height` looking straight down (−y), image up = −z,
// covering x, z ∈ [−mag, mag].
void addTopDownCamera(GltfBuilder& b, float height, float mag) {
  const int cam =
      b.addCamera({{"type", "orthographic"},
                   {"orthographic", {{"xmag", mag}, {"ymag", mag}, {"znear", 0}, {"zfar", 100}}}});
  b.addNode({{"camera", cam}, {"translation", {0, height, 0}}, {"rotation", {-kS, 0, 0, kS}}});
}

// Average of f over the footprint of pixel (px, py) of an n×n top-down image covering ±mag.
template <typename F>
double footprintAverage(int px, int py, int n, float mag, F f, int sub = 8) {
  double sum = 0;
  for (int j = 0; j < sub; ++j)
    for (int i = 0; i < sub; ++i) {
      const double x = (-1 + 2 * (px + (i + 0.5) / sub) / n) * mag;
      const double z = (-1 + 2 * (py + (j + 0.5) / sub) / n) * mag;
      sum += f(x, z);
    }
  return sum / (sub * sub);
}

TEST(AnalyticLighting, LambertianPlaneUnderPointLight) {
  GltfBuilder b;
  const float rho = 0.8f, intensity = 10.0f, h = 2.0f, mag = 1.5f;
  b.addQuad({-5, 0, 5}, {5, 0, 5}, {5, 0, -5}, {-5, 0, -5},
            b.addMaterial(test::lambertianMaterial(rho, rho, rho)));
  const int light = b.addPunctualLight({{"type", "point"}, {"intensity", intensity}});
  b.addNode(
      {{"translation", {0, h, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", light}}}}}});
  addTopDownCamera(b, 1.0f, mag);
  const int n = 16;
  const RenderResult r = renderGltf(b, EnvironmentDesc{}, options(n, 16));
  // E = I cos θ / d² = I h / d³, L = ρ E / π.
  const auto radiance = [&](double x, double z) {
    const double d = std::sqrt(x * x + z * z + h * h);
    return rho / M_PI * intensity * h / (d * d * d);
  };
  const PixelCheck c = checkPixels(
      r.buffers.part(BufferPart::Full),
      [&](int x, int y) { return footprintAverage(x, y, n, mag, radiance); }, 0.002);
  EXPECT_EQ(c.outliers, 0);
  EXPECT_LT(c.meanRelativeError, 0.001);
}

// Form factor from a point to a parallel rectangle [0,a]×[0,b] at distance c with one corner
// above it, extended to signed sides so that rectangles combine by inclusion–exclusion.
double cornerFormFactor(double a, double b, double c) {
  const double x = std::abs(a) / c, y = std::abs(b) / c;
  const double sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
  const double f = (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2 * M_PI);
  return (a < 0) != (b < 0) ? -f : f;
}

// A Lambertian plane (ρ = 0.5) under a square emitter (side 2, radiance 2) at height 1, seen
// from above by an orthographic camera between them, and the exact radiance at (x, z).
struct AreaLitPlane {
  static constexpr float kRho = 0.5f, kLe = 2.0f, kHeight = 1.0f, kHalf = 1.0f, kMag = 1.5f;
  GltfBuilder builder;

  AreaLitPlane() {
    GltfBuilder& b = builder;
    b.addQuad({-5, 0, 5}, {5, 0, 5}, {5, 0, -5}, {-5, 0, -5},
              b.addMaterial(test::lambertianMaterial(kRho, kRho, kRho)));
    json emitter = test::lambertianMaterial(0, 0, 0);
    emitter["emissiveFactor"] = {1, 1, 1};
    emitter["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", kLe}};
    // Facing down: counter-clockwise seen from below.
    b.addQuad({-kHalf, kHeight, -kHalf}, {kHalf, kHeight, -kHalf}, {kHalf, kHeight, kHalf},
              {-kHalf, kHeight, kHalf}, b.addMaterial(emitter));
    addTopDownCamera(b, 0.5f, kMag);
  }
  // L = ρ/π · E = ρ Le F, F summed over the emitter's corners relative to the point.
  static double radiance(double x, double z) {
    const double x0 = -kHalf - x, x1 = kHalf - x, z0 = -kHalf - z, z1 = kHalf - z;
    const double f = cornerFormFactor(x1, z1, kHeight) - cornerFormFactor(x0, z1, kHeight) -
                     cornerFormFactor(x1, z0, kHeight) + cornerFormFactor(x0, z0, kHeight);
    return kRho * kLe * f;
  }
  static double pixel(int x, int y, int n) { return footprintAverage(x, y, n, kMag, radiance, 4); }
};

TEST(AnalyticLighting, LambertianPlaneUnderSquareAreaLight) {
  const AreaLitPlane scene;
  const int n = 12;
  const RenderResult r = renderGltf(scene.builder, EnvironmentDesc{}, options(n, 256));
  const PixelCheck c = checkPixels(
      r.buffers.part(BufferPart::Full), [&](int x, int y) { return AreaLitPlane::pixel(x, y, n); },
      0.02);
  EXPECT_EQ(c.outliers, 0);
  EXPECT_LT(c.meanRelativeError, 0.005);
}

// A thin lens focused at 2 in front of an emitting half-plane at depth 4 (radiance 1, x < 0):
// the image point s (image plane at distance 1) is lit by the lens points L on the unit disk
// with s.x − L.x·k < 0, k = R·(1/2 − 1/4) (the circle of confusion: camera.h), i.e. the part of
// the disk beyond a = s.x / k, of area acos(a) − a·√(1 − a²); each pixel averages it over its
// width. The pinhole render of the same edge is a step.
TEST(AnalyticLighting, ThinLensBlursAnEdgeByItsCircleOfConfusion) {
  GltfBuilder b;
  json emitter = test::lambertianMaterial(0, 0, 0);
  emitter["emissiveFactor"] = {1, 1, 1};
  b.addQuad({-10, -10, -4}, {0, -10, -4}, {0, 10, -4}, {-10, 10, -4}, b.addMaterial(emitter));
  const int cam =
      b.addCamera({{"type", "perspective"}, {"perspective", {{"yfov", kPi / 2}, {"znear", 0.01}}}});
  b.addNode({{"camera", cam}});
  const int n = 48;  // 24 pixels per unit of the image plane (tan 45° = 1)
  RenderOptions o = options(n, 64);
  const auto columns = [&](const RenderResult& r) {
    std::vector<double> mean(size_t(n), 0.0);
    const SubBuffer& full = r.buffers.part(BufferPart::Full);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) mean[size_t(x)] += full.color.mean.at(x, y, 0) / n;
    return mean;
  };
  const std::vector<double> sharp = columns(renderGltf(b, EnvironmentDesc{}, o));
  EXPECT_NEAR(sharp[23], 1.0, 1e-6);
  EXPECT_NEAR(sharp[24], 0.0, 1e-6);
  o.lensRadius = 0.5f;
  o.focusDistance = 2.0f;
  const std::vector<double> blurred = columns(renderGltf(b, EnvironmentDesc{}, o));
  const double k = 0.5 * (1.0 / 2 - 1.0 / 4);  // 3 pixels
  const auto litShare = [&](double sx) {
    const double a = std::clamp(sx / k, -1.0, 1.0);
    return (std::acos(a) - a * std::sqrt(1 - a * a)) / kPi;
  };
  for (int x = 16; x < 32; ++x) {
    double expected = 0;
    const int steps = 200;
    for (int i = 0; i < steps; ++i)
      expected += litShare((x - 24 + (i + 0.5) / steps) / 24.0) / steps;
    EXPECT_NEAR(blurred[size_t(x)], expected, 0.02) << "column " << x;
  }
  // The blur spans three pixels each side of the edge and no more.
  EXPECT_LT(blurred[22], 0.9);
  EXPECT_NEAR(blurred[19], 1.0, 1e-6);
  EXPECT_NEAR(blurred[29], 0.0, 1e-6);
  // An orthographic camera has no lens: one error naming the scene file.
  addTopDownCamera(b, 5, 1);
  o.camera = 1;
  test::TempDir dir;
  b.writeGltf(dir / "ortho.gltf");
  const Scene ortho = buildScene(loadGltf(dir / "ortho.gltf"), EnvironmentDesc{});
  try {
    render(ortho, o);
    ADD_FAILURE() << "a lens on an orthographic camera rendered";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ortho.gltf"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("orthographic"), std::string::npos) << e.what();
  }
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = double(a.size());
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / n;
  const double mb = std::accumulate(b.begin(), b.end(), 0.0) / n;
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

// Errors against the exact image (so no reference noise is shared): across pixels, half A's and
// half B's errors must be uncorrelated, and so must those of two quarters.
TEST(SubBuffers, HalvesHaveUncorrelatedErrors) {
  const AreaLitPlane scene;
  const int n = 64;
  RenderOptions o = options(n, 8);
  o.splits = 4;
  const SampleBuffers buffers = renderGltf(scene.builder, EnvironmentDesc{}, o).buffers;
  const SubBuffer a = buffers.part(BufferPart::HalfA), b = buffers.part(BufferPart::HalfB);
  std::vector<double> errorA, errorB, errorQ0, errorQ1;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double truth = AreaLitPlane::pixel(x, y, n);
      errorA.push_back(a.color.mean.at(x, y, 0) - truth);
      errorB.push_back(b.color.mean.at(x, y, 0) - truth);
      errorQ0.push_back(buffers.sub(0).color.mean.at(x, y, 0) - truth);
      errorQ1.push_back(buffers.sub(1).color.mean.at(x, y, 0) - truth);
    }
  const double rho = correlation(errorA, errorB);
  RecordProperty("rho", std::to_string(rho));
  EXPECT_LT(std::abs(rho), 0.05);
  EXPECT_LT(std::abs(correlation(errorQ0, errorQ1)), 0.05);
  // Sample i goes to sub-buffer i mod 4: two samples each.
  for (int k = 0; k < 4; ++k) EXPECT_EQ(buffers.sub(k).sampleCount.at(5, 7, 0), 2.0f);
}

TEST(AnalyticLighting, LambertianSphereUnderEnvironmentMapMatchesQuadrature) {
  test::TempDir dir;
  const int w = 32, h = 16;
  std::vector<float> texels(size_t(w * h * 3));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        texels[size_t((y * w + x) * 3 + c)] = 0.2f + (y < 5 ? 2.0f : 0.0f) + 0.5f * float(x) / w;
  const std::filesystem::path hdr = dir / "env.hdr";
  ASSERT_NE(stbi_write_hdr(hdr.c_str(), w, h, 3, texels.data()), 0);
  const EnvironmentDesc env = environmentFromFile(hdr, 0.0f, 1.0f);

  GltfBuilder b;
  const float rho = 0.9f;
  b.addSphere({0, 0, 0}, 1.0f, b.addMaterial(test::lambertianMaterial(rho, rho, rho)), 128);
  const int cam =
      b.addCamera({{"type", "orthographic"},
                   {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0}, {"zfar", 10}}}});
  b.addNode({{"camera", cam}, {"translation", {0, 0, 3}}});
  const int n = 12;
  const RenderResult r = renderGltf(b, env, options(n, 256));

  // Irradiance at normal nrm from the piecewise-constant map, by quadrature over each texel.
  const auto irradiance = [&](Vec3f nrm) {
    double e = 0;
    const int sub = 4;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int j = 0; j < sub; ++j)
          for (int i = 0; i < sub; ++i) {
            const double u = (x + (i + 0.5) / sub) / w, v = (y + (j + 0.5) / sub) / h;
            const double theta = v * M_PI, phi = (u - 0.5) * 2 * M_PI;
            const Vec3f d{float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)),
                          float(-std::sin(theta) * std::cos(phi))};
            const double dOmega = (2 * M_PI / (w * sub)) * (M_PI / (h * sub)) * std::sin(theta);
            e += texels[size_t((y * w + x) * 3)] * std::max(0.0f, dot(nrm, d)) * dOmega;
          }
    return e;
  };
  const PixelCheck c = checkPixels(
      r.buffers.part(BufferPart::Full),
      [&](int px, int py) {
        const float x = -1 + 2 * (px + 0.5f) / n, y = 1 - 2 * (py + 0.5f) / n;
        if (x * x + y * y > 0.7f) return -1.0;  // near the silhouette the footprint is curved
        return rho / M_PI * irradiance({x, y, std::sqrt(1 - x * x - y * y)});
      },
      0.02);
  EXPECT_GT(c.checked, 40);
  EXPECT_EQ(c.outliers, 0);
  EXPECT_LT(c.meanRelativeError, 0.01);
}

}  // namespace
}  // namespace chorus::render
