// The runtime scene: intersection and surface data, robust ray offsets at every scale (no
// self-intersection, no leaks out of closed boxes), alpha testing, the default environment.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "renderer/integrator/ray_offset.h"
#include "renderer/sampling/warps.h"
#include "renderer/scene/gltf_loader.h"
#include "renderer/scene/scene.h"
#include "tests/support/gltf_builder.h"
#include "tests/support/test_support.h"

namespace chorus::render {
namespace {

// A closed axis-aligned box with outward faces (12 triangles), centred at `c`, half size `h`.
MeshDesc closedBox(Vec3f c, float h) {
  MeshDesc m;
  for (int i = 0; i < 8; ++i)
    m.positions.push_back(c + Vec3f{i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h});
  m.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
               2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  return m;
}

SceneDesc sceneWith(std::vector<MeshDesc> meshes) {
  SceneDesc desc;
  desc.materials.push_back(MaterialDesc{});
  for (MeshDesc& m : meshes) {
    for (const Vec3f& p : m.positions) desc.bounds.extend(p);
    desc.meshes.push_back(std::move(m));
  }
  return desc;
}

TEST(Scene, InteractionReportsPositionNormalsAndUv) {
  MeshDesc quad;
  quad.positions = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}};
  quad.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  const Scene scene = buildScene(sceneWith({quad}), EnvironmentDesc{});
  Hit hit;
  ASSERT_TRUE(scene.intersect({{1.5f, 0.5f, 5}, {0, 0, -1}}, &hit));
  EXPECT_FLOAT_EQ(hit.t, 5.0f);
  const SurfaceInteraction si = scene.interaction(hit, {0, 0, -1});
  EXPECT_NEAR(si.position.x, 1.5f, 1e-6f);
  EXPECT_NEAR(si.position.y, 0.5f, 1e-6f);
  EXPECT_NEAR(si.uv.x, 0.75f, 1e-6f);
  EXPECT_NEAR(si.uv.y, 0.25f, 1e-6f);
  EXPECT_FLOAT_EQ(si.geometricNormal.z, 1.0f);
  EXPECT_FLOAT_EQ(si.shadingNormal.z, 1.0f);
  EXPECT_TRUE(si.frontFace);
  EXPECT_FALSE(scene.intersect({{3, 3, 5}, {0, 0, -1}}, &hit));
  EXPECT_TRUE(scene.occluded({1, 1, 1}, {0, 0, -2}, 1.0f));
  EXPECT_FALSE(scene.occluded({1, 1, 1}, {0, 0, -2}, 0.4f));
}

TEST(Scene, NoLightMeansDefaultWhiteEnvironment) {
  const Scene dark = buildScene(sceneWith({closedBox({0, 0, 0}, 1)}), EnvironmentDesc{});
  EXPECT_TRUE(dark.usesDefaultEnvironment());
  EXPECT_EQ(dark.environment().kind, EnvironmentDesc::Kind::Constant);
  EXPECT_FLOAT_EQ(dark.environment().radiance.g, 1.0f);
  const Scene lit =
      buildScene(sceneWith({closedBox({0, 0, 0}, 1)}), EnvironmentDesc::constant(Rgb(0.25f)));
  EXPECT_FALSE(lit.usesDefaultEnvironment());
  EXPECT_FLOAT_EQ(lit.environment().radiance.g, 0.25f);
}

// Rays leaving random points of a box's inside in random inward directions must hit the box
// again (no leak) and never on the face they left (no self-intersection), at scales
// from millimetres to kilometres and far from the origin.
TEST(Scene, RayOffsetsNeitherSelfIntersectNorLeakAtAnyScale) {
  for (float scale : {1e-3f, 1.0f, 1e3f}) {
    for (Vec3f centre : {Vec3f{0, 0, 0}, Vec3f{1000, -2000, 500}}) {
      const Vec3f c = centre * scale;
      const Scene scene = buildScene(sceneWith({closedBox(c, scale)}), EnvironmentDesc{});
      std::mt19937 rng(17);
      std::uniform_real_distribution<float> u(0.0f, 1.0f);
      int selfHits = 0, leaks = 0;
      for (int i = 0; i < 4000; ++i) {
        // A first hit from the centre, then a bounce into the inward hemisphere.
        const Vec3f d0 = sampleUniformSphere({u(rng), u(rng)});
        Hit hit;
        ASSERT_TRUE(scene.intersect({c, d0}, &hit));
        const SurfaceInteraction si = scene.interaction(hit, d0);
        const Vec3f inward = -si.geometricNormal;
        Vec3f d1 = sampleUniformSphere({u(rng), u(rng)});
        if (dot(d1, inward) < 0) d1 = -d1;
        if (i % 4 == 0) {
          // Grazing: almost parallel to the face.
          const Vec3f tangent = d1 - inward * dot(d1, inward);
          if (length(tangent) > 0) d1 = normalize(normalize(tangent) + inward * 1e-3f);
        }
        if (!(dot(d1, inward) > 0)) continue;
        const Vec3f origin = offsetRayOrigin(si.position, si.positionError, si.geometricNormal, d1);
        Hit next;
        if (!scene.intersect({origin, d1}, &next)) {
          ++leaks;
          continue;
        }
        // Each face is two consecutive triangles; leaving a face inward can never hit it again.
        if (next.primID / 2 == hit.primID / 2) ++selfHits;
      }
      EXPECT_EQ(selfHits, 0) << "scale " << scale << " centre " << centre.x;
      EXPECT_EQ(leaks, 0) << "scale " << scale << " centre " << centre.x;
    }
  }
}

// A plane lying exactly on a coordinate plane has no rounding error along its normal: the
// offset must still move rays off it.
TEST(Scene, RaysLeaveAPlaneAtZeroCoordinate) {
  MeshDesc quad;
  quad.positions = {{-3, 0, -3}, {3, 0, -3}, {3, 0, 3}, {-3, 0, 3}};
  quad.indices = {0, 2, 1, 0, 3, 2};
  const Scene scene = buildScene(sceneWith({quad}), EnvironmentDesc{});
  std::mt19937 rng(29);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int selfHits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3f start{4 * u(rng) - 2, 1, 4 * u(rng) - 2};
    Hit hit;
    ASSERT_TRUE(scene.intersect({start, {0, -1, 0}}, &hit));
    const SurfaceInteraction si = scene.interaction(hit, {0, -1, 0});
    Vec3f d = sampleUniformSphere({u(rng), u(rng)});
    if (d.y < 0) d.y = -d.y;
    const Vec3f origin = offsetRayOrigin(si.position, si.positionError, si.geometricNormal, d);
    selfHits += scene.occluded(origin, d, std::numeric_limits<float>::infinity());
  }
  EXPECT_EQ(selfHits, 0);
}

TEST(Scene, AlphaMaskCutsOutTexelsAndBlendKeepsAFractionOfHits) {
  test::TempDir dir;
  test::GltfBuilder b;
  // 2×1 texture: left texel opaque, right texel alpha 0.2.
  const int tex =
      b.addTexture(2, 1, {255, 255, 255, 255, 255, 255, 255, 51}, {{"magFilter", 9728}});
  nlohmann::json mask = {{"alphaMode", "MASK"},
                         {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", tex}}}}}};
  nlohmann::json blend = {{"alphaMode", "BLEND"},
                          {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.3}}}}};
  b.addQuad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, b.addMaterial(mask));
  b.addQuad({0, 0, -1}, {1, 0, -1}, {1, 1, -1}, {0, 1, -1}, b.addMaterial(blend));
  b.writeGltf(dir / "alpha.gltf");
  const Scene scene = buildScene(loadGltf(dir / "alpha.gltf"), EnvironmentDesc{});
  Hit hit;
  // Left half (u < 0.5) of the masked quad is opaque, the right half is cut out.
  ASSERT_TRUE(scene.intersect({{0.25f, 0.5f, 1}, {0, 0, -1}}, &hit));
  EXPECT_FLOAT_EQ(hit.t, 1.0f);
  EXPECT_TRUE(scene.occluded({0.25f, 0.5f, 1}, {0, 0, -1}, 1.5f));
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int blendHits = 0, misses = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Vec3f origin{0.55f + 0.4f * u(rng), 0.05f + 0.9f * u(rng), 1};
    if (!scene.intersect({origin, {0, 0, -1}}, &hit)) {
      ++misses;
      continue;
    }
    EXPECT_FLOAT_EQ(hit.t, 2.0f);  // never the cut-out front quad
    ++blendHits;
  }
  EXPECT_NEAR(double(blendHits) / n, 0.3, 0.015);
  EXPECT_EQ(blendHits + misses, n);
}

}  // namespace
}  // namespace chorus::render
