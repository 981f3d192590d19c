// LaneTracer (four paths in SIMD lanes) against the one-path PathTracer it stands in for: the
// same buffers bit for bit on every scene it takes, and the scenes it must leave to the general
// tracer.
#include <gtest/gtest.h>

#include <algorithm>

#include "renderer/integrator/lane_tracer.h"
#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tests/support/gltf_builder.h"
#include "tests/support/test_support.h"

namespace chorus::render {
namespace {

using nlohmann::json;
using test::GltfBuilder;

RenderOptions options(int width, int height, int spp, int splits) {
  RenderOptions o;
  o.width = width;
  o.height = height;
  o.spp = spp;
  o.splits = splits;
  o.seed = 11;
  o.threads = 2;
  return o;
}

bool sameImage(const Image& a, const Image& b) {
  return a.values().size() == b.values().size() &&
         std::equal(a.values().begin(), a.values().end(), b.values().begin());
}

// Renders with lanes and without and expects equal buffers, mean and variance of every
// quantity of every sub-buffer; returns the scalar render's mean colour for sanity checks.
double expectLanesEqualScalar(const Scene& scene, RenderOptions o) {
  o.lanes = false;
  const RenderResult scalar = render(scene, o);
  o.lanes = true;
  const RenderResult lanes = render(scene, o);
  for (int k = 0; k < o.splits; ++k)
    for (Quantity q : kAllQuantities) {
      EXPECT_TRUE(sameImage(scalar.buffers.sub(k).get(q).mean, lanes.buffers.sub(k).get(q).mean))
          << quantityName(q) << " mean, sub-buffer " << k;
      EXPECT_TRUE(sameImage(scalar.buffers.sub(k).get(q).varianceOfMean,
                            lanes.buffers.sub(k).get(q).varianceOfMean))
          << quantityName(q) << " variance, sub-buffer " << k;
    }
  EXPECT_FALSE(scalar.stats.lanes);
  EXPECT_TRUE(lanes.stats.lanes);
  EXPECT_EQ(scalar.stats.rays, lanes.stats.rays);
  EXPECT_EQ(scalar.stats.shadowRays, lanes.stats.shadowRays);
  EXPECT_EQ(scalar.stats.nanSamplesDropped, lanes.stats.nanSamplesDropped);
  const auto& v = scalar.buffers.sub(0).color.mean.values();
  double sum = 0;
  for (float x : v) sum += double(x);
  return sum / double(v.size());
}

Scene loadScene(const std::filesystem::path& path, EnvironmentDesc environment = {}) {
  return buildScene(loadGltf(path), environment);
}

TEST(LaneTracer, CornellBoxBitIdenticalToTheScalarTracer) {
  const Scene scene = loadScene(test::sourceDir() / "scenes/cornell-box.gltf");
  ASSERT_TRUE(LaneTracer::create(scene, LightSet(scene), PathTracerSettings{}).has_value());
  // 37×29: partial tiles, lanes that run out of pixels at different times.
  const double mean = expectLanesEqualScalar(scene, options(37, 29, 6, 2));
  EXPECT_GT(mean, 0.01);  // lit, not an empty comparison
  expectLanesEqualScalar(scene, options(20, 16, 8, 4));
  // Every path to full depth, and paths cut at the first bounce.
  RenderOptions deep = options(16, 16, 4, 1);
  deep.rouletteStartDepth = 100;
  expectLanesEqualScalar(scene, deep);
  RenderOptions shallow = options(16, 16, 4, 1);
  shallow.maxDepth = 1;
  expectLanesEqualScalar(scene, shallow);
}

// Double-sided and one-sided emitters seen from both sides, two light sources of different
// power, walls seen from behind and rays escaping to the (black) background.
Scene openRoom(const test::TempDir& dir) {
  GltfBuilder b;
  b.addQuad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3},
            b.addMaterial(test::lambertianMaterial(0.7f, 0.6f, 0.5f)));
  b.addQuad({-1, 0, -1}, {-1, 1.5f, -1}, {-1, 1.5f, 1}, {-1, 0, 1},  // faces −x, seen from behind
            b.addMaterial(test::lambertianMaterial(0.2f, 0.8f, 0.3f)));
  json oneSided = test::lambertianMaterial(0, 0, 0);
  oneSided["emissiveFactor"] = {4, 3, 2};
  b.addQuad({-0.5f, 2, -0.5f}, {0.5f, 2, -0.5f}, {0.5f, 2, 0.5f}, {-0.5f, 2, 0.5f},
            b.addMaterial(oneSided));
  json twoSided = test::lambertianMaterial(0.5f, 0.5f, 0.5f);
  twoSided["emissiveFactor"] = {0.5, 1, 2};
  twoSided["doubleSided"] = true;
  b.addQuad({1, 0.2f, -0.5f}, {1, 0.2f, 0.5f}, {1, 1.2f, 0.5f}, {1, 1.2f, -0.5f},
            b.addMaterial(twoSided));
  const int cam =
      b.addCamera({{"type", "perspective"}, {"perspective", {{"yfov", 1.2}, {"znear", 0.01}}}});
  b.addNode({{"camera", cam}, {"translation", {0, 1.2, 3}}, {"rotation", {-0.17, 0, 0, 0.985}}});
  b.writeGltf(dir / "open.gltf");
  return loadScene(dir / "open.gltf");
}

TEST(LaneTracer, OpenRoomWithTwoSidedEmittersBitIdentical) {
  test::TempDir dir;
  const Scene scene = openRoom(dir);
  ASSERT_TRUE(LaneTracer::create(scene, LightSet(scene), PathTracerSettings{}).has_value());
  EXPECT_GT(expectLanesEqualScalar(scene, options(33, 21, 5, 1)), 0.01);
}

TEST(LaneTracer, LeavesOtherScenesToTheGeneralTracer) {
  test::TempDir dir;
  const auto accepts = [](const Scene& scene) {
    return LaneTracer::create(scene, LightSet(scene), PathTracerSettings{}).has_value();
  };
  const auto room = [&](json floorMaterial, bool pointLight, bool sphere) {
    GltfBuilder b;
    b.addQuad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}, b.addMaterial(floorMaterial));
    json emitter = test::lambertianMaterial(0, 0, 0);
    emitter["emissiveFactor"] = {1, 1, 1};
    b.addQuad({-0.5f, 2, -0.5f}, {0.5f, 2, -0.5f}, {0.5f, 2, 0.5f}, {-0.5f, 2, 0.5f},
              b.addMaterial(emitter));
    if (sphere)  // smooth vertex normals: the shading normal varies over each triangle
      b.addSphere({0, 0.5f, 0}, 0.5f, b.addMaterial(test::lambertianMaterial(0.5f, 0.5f, 0.5f)), 8);
    if (pointLight) {
      const int light = b.addPunctualLight({{"type", "point"}, {"intensity", 5}});
      b.addNode({{"translation", {0, 1, 0}},
                 {"extensions", {{"KHR_lights_punctual", {{"light", light}}}}}});
    }
    b.writeGltf(dir / "room.gltf");
    return loadScene(dir / "room.gltf");
  };
  const json lambertian = test::lambertianMaterial(0.5f, 0.5f, 0.5f);
  EXPECT_TRUE(accepts(room(lambertian, false, false)));
  EXPECT_FALSE(accepts(room(lambertian, true, false)));
  EXPECT_FALSE(accepts(room(lambertian, false, true)));
  json metal = {{"pbrMetallicRoughness", {{"metallicFactor", 1.0}, {"roughnessFactor", 0.3}}}};
  EXPECT_FALSE(accepts(room(metal, false, false)));
  json layered = {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}};  // default specular layer
  EXPECT_FALSE(accepts(room(layered, false, false)));
  // An environment that emits.
  GltfBuilder b;
  b.addQuad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3}, b.addMaterial(lambertian));
  b.writeGltf(dir / "unlit.gltf");
  EXPECT_FALSE(accepts(loadScene(dir / "unlit.gltf")));  // the default white environment
  EXPECT_FALSE(accepts(loadScene(dir / "unlit.gltf", EnvironmentDesc::constant(Rgb(0.5f)))));
}

}  // namespace
}  // namespace chorus::render
