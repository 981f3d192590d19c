// Statistical properties of render(): error convergence with spp, determinism across thread
// counts, and the features (noise-free where they must
// be, the documented values for escaped rays, visibility as a shadow mask).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tests/support/gltf_builder.h"
#include "tests/support/test_support.h"

namespace chorus::render {
namespace {

using nlohmann::json;
using test::GltfBuilder;

const float kS = std::sqrt(0.5f);

// A floor, a diffuse sphere and a glossy one under a square area light, seen at an angle:
// direct and indirect light, soft shadows, MIS between light and BSDF sampling.
Scene smallRoom(const test::TempDir& dir) {
  GltfBuilder b;
  b.addQuad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3},
            b.addMaterial(test::lambertianMaterial(0.7f, 0.7f, 0.7f)));
  b.addSphere({-0.6f, 0.5f, 0}, 0.5f, b.addMaterial(test::lambertianMaterial(0.8f, 0.3f, 0.2f)),
              32);
  b.addSphere({0.7f, 0.4f, 0.3f}, 0.4f,
              b.addMaterial(
                  {{"pbrMetallicRoughness", {{"metallicFactor", 1.0}, {"roughnessFactor", 0.3}}}}),
              32);
  json emitter = test::lambertianMaterial(0, 0, 0);
  emitter["emissiveFactor"] = {1, 1, 1};
  emitter["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", 6.0}};
  b.addQuad({-0.5f, 2, -0.5f}, {0.5f, 2, -0.5f}, {0.5f, 2, 0.5f}, {-0.5f, 2, 0.5f},
            b.addMaterial(emitter));
  const int cam =
      b.addCamera({{"type", "perspective"}, {"perspective", {{"yfov", 0.9}, {"znear", 0.01}}}});
  b.addNode({{"camera", cam}, {"translation", {0, 1.2, 3}}, {"rotation", {-0.17, 0, 0, 0.985}}});
  b.writeGltf(dir / "room.gltf");
  return buildScene(loadGltf(dir / "room.gltf"), EnvironmentDesc{});
}

RenderOptions options(int size, int spp, int splits, uint64_t seed) {
  RenderOptions o;
  o.width = o.height = size;
  o.spp = spp;
  o.splits = splits;
  o.seed = seed;
  return o;
}

double meanOf(const Image& image) {
  return std::accumulate(image.values().begin(), image.values().end(), 0.0) / double(image.size());
}

TEST(RenderStatistics, MeanSquaredErrorFallsAsOneOverSpp) {
  test::TempDir dir;
  const Scene scene = smallRoom(dir);
  const int size = 16;
  const SubBuffer reference = render(scene, options(size, 2048, 1, 99)).buffers.sub(0);
  // The reference's own noise adds its variance to every MSE: subtract its estimate.
  const double referenceNoise = meanOf(reference.color.varianceOfMean);
  std::vector<double> logSpp, logMse;
  for (int spp : {4, 8, 16, 32, 64}) {
    double mse = 0;
    const int repeats = 4;  // average over seeds to steady the estimate
    for (int seed = 0; seed < repeats; ++seed) {
      const SubBuffer b = render(scene, options(size, spp, 1, uint64_t(seed))).buffers.sub(0);
      for (size_t i = 0; i < b.color.mean.size(); ++i) {
        const double d = double(b.color.mean.data()[i]) - reference.color.mean.data()[i];
        mse += d * d;
      }
    }
    mse = mse / (repeats * double(reference.color.mean.size())) - referenceNoise;
    ASSERT_GT(mse, 0.0);
    logSpp.push_back(std::log(spp));
    logMse.push_back(std::log(mse));
  }
  // Least-squares slope of log MSE against log spp.
  const double n = double(logSpp.size());
  const double mx = std::accumulate(logSpp.begin(), logSpp.end(), 0.0) / n;
  const double my = std::accumulate(logMse.begin(), logMse.end(), 0.0) / n;
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < logSpp.size(); ++i) {
    sxy += (logSpp[i] - mx) * (logMse[i] - my);
    sxx += (logSpp[i] - mx) * (logSpp[i] - mx);
  }
  const double slope = sxy / sxx;
  RecordProperty("slope", std::to_string(slope));
  EXPECT_GT(slope, -1.2);
  EXPECT_LT(slope, -0.8);
}

TEST(RenderStatistics, BitIdenticalForOneAndTwoThreads) {
  test::TempDir dir;
  const Scene scene = smallRoom(dir);
  RenderOptions o = options(24, 8, 2, 5);
  o.threads = 1;
  const SampleBuffers one = render(scene, o).buffers;
  o.threads = 2;
  const SampleBuffers two = render(scene, o).buffers;
  for (int k = 0; k < 2; ++k)
    for (Quantity q : kAllQuantities) {
      EXPECT_EQ(one.sub(k).get(q).mean.values().size(), two.sub(k).get(q).mean.values().size());
      EXPECT_TRUE(std::equal(one.sub(k).get(q).mean.values().begin(),
                             one.sub(k).get(q).mean.values().end(),
                             two.sub(k).get(q).mean.values().begin()))
          << quantityName(q);
      EXPECT_TRUE(std::equal(one.sub(k).get(q).varianceOfMean.values().begin(),
                             one.sub(k).get(q).varianceOfMean.values().end(),
                             two.sub(k).get(q).varianceOfMean.values().begin()))
          << quantityName(q);
    }
  // A different seed gives a different image.
  o.seed = 6;
  const SampleBuffers other = render(scene, o).buffers;
  EXPECT_FALSE(std::equal(one.sub(0).color.mean.values().begin(),
                          one.sub(0).color.mean.values().end(),
                          other.sub(0).color.mean.values().begin()));
}

// An orthographic camera facing a flat wall (the plane z = 0, facing +z) lit by a point light;
// the right half of the wall is shadowed by a thin blocker; the top rows see past the wall.
Scene wallScene(const test::TempDir& dir) {
  GltfBuilder b;
  b.addQuad({-2, -2, 0}, {2, -2, 0}, {2, 1, 0}, {-2, 1, 0},
            b.addMaterial(test::lambertianMaterial(0.25f, 0.5f, 0.75f)));
  // Blocker between the light at z = 4 and the right half of the wall, outside the view.
  b.addQuad({0, -3, 2}, {3, -3, 2}, {3, 3, 2}, {0, 3, 2},
            b.addMaterial(test::lambertianMaterial(0, 0, 0)));
  const int light = b.addPunctualLight({{"type", "point"}, {"intensity", 5}});
  b.addNode({{"translation", {-0.5, 0, 4}},
             {"extensions", {{"KHR_lights_punctual", {{"light", light}}}}}});
  const int cam =
      b.addCamera({{"type", "orthographic"},
                   {"orthographic", {{"xmag", 1.5}, {"ymag", 1.5}, {"znear", 0}, {"zfar", 10}}}});
  b.addNode({{"camera", cam}, {"translation", {0, 0, 1.5}}});
  b.writeGltf(dir / "wall.gltf");
  return buildScene(loadGltf(dir / "wall.gltf"), EnvironmentDesc{});
}

TEST(RenderFeatures, FlatDiffuseWallHasNoiseFreeFeaturesAndDocumentedEscapes) {
  test::TempDir dir;
  const Scene scene = wallScene(dir);
  const int n = 24;
  const SubBuffer full = render(scene, options(n, 16, 2, 1)).buffers.part(BufferPart::Full);
  int wallPixels = 0, escapedPixels = 0, shadowed = 0, lit = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const float worldX = -1.5f + 3.0f * (x + 0.5f) / n, worldYTop = 1.5f - 3.0f * y / n;
      const float worldYBottom = 1.5f - 3.0f * (y + 1) / n;
      if (worldYTop <= 1.0f) {
        ++wallPixels;
        EXPECT_FLOAT_EQ(full.albedo.mean.at(x, y, 0), 0.25f);
        EXPECT_FLOAT_EQ(full.albedo.mean.at(x, y, 2), 0.75f);
        EXPECT_FLOAT_EQ(full.normal.mean.at(x, y, 2), 1.0f);
        EXPECT_FLOAT_EQ(full.depth.mean.at(x, y, 0), 1.5f);
        for (Quantity q : {Quantity::Albedo, Quantity::Normal, Quantity::Depth})
          for (int c = 0; c < channelCount(q); ++c)
            EXPECT_EQ(full.get(q).varianceOfMean.at(x, y, c), 0.0f)
                << quantityName(q) << " " << x << "," << y;
        // The blocker's shadow edge on the wall: the ray from the light (−0.5, 0, 4) past the
        // blocker edge (0, ·, 2) reaches z = 0 at x = 0.5. Pixels clearly on one side:
        const float vis = full.visibility.mean.at(x, y, 0);
        if (worldX > 0.6f) {
          EXPECT_EQ(vis, 0.0f);
          EXPECT_EQ(full.color.mean.at(x, y, 0), 0.0f);
          ++shadowed;
        } else if (worldX < 0.4f) {
          EXPECT_EQ(vis, 1.0f);
          EXPECT_EQ(full.visibility.varianceOfMean.at(x, y, 0), 0.0f);
          ++lit;
        }
      } else if (worldYBottom > 1.0f) {
        ++escapedPixels;
        EXPECT_EQ(full.albedo.mean.at(x, y, 1), 1.0f);
        EXPECT_EQ(full.normal.mean.at(x, y, 1), 0.0f);
        EXPECT_EQ(full.depth.mean.at(x, y, 0), 0.0f);
        EXPECT_EQ(full.visibility.mean.at(x, y, 0), 1.0f);
        EXPECT_EQ(full.color.mean.at(x, y, 0), 0.0f);  // no environment: the light is punctual
      }
    }
  EXPECT_GT(wallPixels, 300);
  EXPECT_GT(escapedPixels, 50);
  EXPECT_GT(shadowed, 10);
  EXPECT_GT(lit, 100);
}

}  // namespace
}  // namespace chorus::render
