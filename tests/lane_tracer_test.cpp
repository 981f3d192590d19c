// LaneTracer (four paths in SIMD lanes) against the one-path PathTracer it stands in for: the
// same buffers bit for bit, on scenes that exercise each of its lane and one-by-one paths.
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>

#include "renderer/integrator/lane_tracer.h"
#include "renderer/render.h"
#include "renderer/scene/gltf_loader.h"
#include "tests/support/gltf_builder.h"
#include "tests/support/test_support.h"
#include "tests/support/tracer_comparison.h"

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

Scene loadScene(const std::filesystem::path& path, EnvironmentDesc environment = {}) {
  return buildScene(loadGltf(path), environment);
}

TEST(LaneTracer, CornellBoxBitIdenticalToTheScalarTracer) {
  const Scene scene = loadScene(test::sourceDir() / "scenes/cornell-box.gltf");
  // 37×29: partial tiles, lanes that run out of pixels at different times.
  const double mean = test::expectTracersAgree(scene, options(37, 29, 6, 2));
  EXPECT_GT(mean, 0.01);  // lit, not an empty comparison
  test::expectTracersAgree(scene, options(20, 16, 8, 4));
  // Every path to full depth, and paths cut at the first bounce.
  RenderOptions deep = options(16, 16, 4, 1);
  deep.rouletteStartDepth = 100;
  test::expectTracersAgree(scene, deep);
  RenderOptions shallow = options(16, 16, 4, 1);
  shallow.maxDepth = 1;
  test::expectTracersAgree(scene, shallow);
}

// Every kind of light and surface the lane tracer takes, in one open room: one- and two-sided
// emitters, a black emitter body, a smooth sphere (shading normals from the vertices), walls
// seen from behind, point and spot lights, and an environment (constant or a map) that escaping
// rays see and next-event estimation samples.
Scene openRoom(const test::TempDir& dir, EnvironmentDesc environment) {
  GltfBuilder b;
  b.addQuad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3},
            b.addMaterial(test::lambertianMaterial(0.7f, 0.6f, 0.5f)));
  b.addQuad({-1, 0, -1}, {-1, 1.5f, -1}, {-1, 1.5f, 1}, {-1, 0, 1},  // faces −x, seen from behind
            b.addMaterial(test::lambertianMaterial(0.2f, 0.8f, 0.3f)));
  b.addSphere({0.2f, 0.5f, 0.3f}, 0.45f, b.addMaterial(test::lambertianMaterial(0.9f, 0.9f, 0.9f)),
              24);
  json oneSided = test::lambertianMaterial(0, 0, 0);
  oneSided["emissiveFactor"] = {4, 3, 2};
  b.addQuad({-0.5f, 2, -0.5f}, {0.5f, 2, -0.5f}, {0.5f, 2, 0.5f}, {-0.5f, 2, 0.5f},
            b.addMaterial(oneSided));
  json twoSided = test::lambertianMaterial(0.5f, 0.5f, 0.5f);
  twoSided["emissiveFactor"] = {0.5, 1, 2};
  twoSided["doubleSided"] = true;
  b.addQuad({1, 0.2f, -0.5f}, {1, 0.2f, 0.5f}, {1, 1.2f, 0.5f}, {1, 1.2f, -0.5f},
            b.addMaterial(twoSided));
  const int point = b.addPunctualLight({{"type", "point"}, {"intensity", 3}});
  b.addNode({{"translation", {-0.5, 1, 1}},
             {"extensions", {{"KHR_lights_punctual", {{"light", point}}}}}});
  const int spot =
      b.addPunctualLight({{"type", "spot"}, {"intensity", 6}, {"spot", {{"outerConeAngle", 0.6}}}});
  b.addNode({{"translation", {0, 1.8, 0}},
             {"rotation", {-0.7071, 0, 0, 0.7071}},
             {"extensions", {{"KHR_lights_punctual", {{"light", spot}}}}}});
  const int cam =
      b.addCamera({{"type", "perspective"}, {"perspective", {{"yfov", 1.2}, {"znear", 0.01}}}});
  b.addNode({{"camera", cam}, {"translation", {0, 1.2, 3}}, {"rotation", {-0.17, 0, 0, 0.985}}});
  b.writeGltf(dir / "open.gltf");
  return loadScene(dir / "open.gltf", environment);
}

TEST(LaneTracer, OpenRoomWithEveryKindOfLightBitIdentical) {
  test::TempDir dir;
  const Scene lit = openRoom(dir, EnvironmentDesc{});
  EXPECT_GT(test::expectTracersAgree(lit, options(33, 21, 5, 1)), 0.01);
  const Scene sky = openRoom(dir, EnvironmentDesc::constant(Rgb(0.3f, 0.4f, 0.6f)));
  test::expectTracersAgree(sky, options(17, 15, 4, 2));
  // Emission taken out of the colour: seen directly, on the black and the two-sided emitters'
  // edges, and in the sky.
  RenderOptions separated = options(17, 15, 4, 2);
  separated.separateEmission = true;
  test::expectTracersAgree(lit, separated);
  test::expectTracersAgree(sky, separated);
  // An equirectangular map with a bright band, importance-sampled.
  const int w = 16, h = 8;
  std::vector<float> texels(size_t(w * h * 3));
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = (i / 3) % size_t(w) < 4 ? 5.0f : 0.2f;
  const std::filesystem::path hdr = dir / "env.hdr";
  ASSERT_NE(stbi_write_hdr(hdr.c_str(), w, h, 3, texels.data()), 0);
  test::expectTracersAgree(openRoom(dir, environmentFromFile(hdr, 30.0f, 1.0f)),
                           options(17, 15, 4, 4));
}

// Surfaces the lanes hand to their Bsdf one by one: glass with a volume, smooth and rough
// metal, textured and normal-mapped materials with the default specular layer (the project's
// own scenes), and alpha-masked, textured-emission and glossy surfaces in lanes next to
// Lambertian ones.
TEST(LaneTracer, EveryOtherMaterialBitIdentical) {
  test::expectTracersAgree(loadScene(test::sourceDir() / "scenes/glass-and-metal.gltf"),
                           options(29, 23, 6, 2));
  // Emission seen in mirrors and not through glass.
  RenderOptions separated = options(29, 23, 6, 2);
  separated.separateEmission = true;
  test::expectTracersAgree(loadScene(test::sourceDir() / "scenes/glass-and-metal.gltf"), separated);
  test::expectTracersAgree(loadScene(test::sourceDir() / "scenes/punctual-lights.gltf"),
                           options(29, 23, 6, 4));

  test::TempDir dir;
  GltfBuilder b;
  std::vector<uint8_t> rgba;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      const bool on = (x + y) % 2 == 0;
      rgba.insert(rgba.end(),
                  {uint8_t(on ? 230 : 40), 120, uint8_t(on ? 30 : 200), uint8_t(on ? 255 : 0)});
    }
  const int texture = b.addTexture(4, 4, rgba);
  b.addQuad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3},
            b.addMaterial(test::lambertianMaterial(0.7f, 0.7f, 0.7f)));
  json leaves = test::lambertianMaterial(1, 1, 1);
  leaves["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", texture}};
  leaves["alphaMode"] = "MASK";
  leaves["doubleSided"] = true;
  b.addQuad({-1, 0.1f, -0.5f}, {1, 0.1f, -0.5f}, {1, 1.5f, -0.5f}, {-1, 1.5f, -0.5f},
            b.addMaterial(leaves));
  json sign = test::lambertianMaterial(0, 0, 0);
  sign["emissiveFactor"] = {3, 3, 3};
  sign["emissiveTexture"] = {{"index", texture}};
  b.addQuad({-0.5f, 2, -0.5f}, {0.5f, 2, -0.5f}, {0.5f, 2, 0.5f}, {-0.5f, 2, 0.5f},
            b.addMaterial(sign));
  b.addSphere({0.6f, 0.4f, 0.4f}, 0.4f,
              b.addMaterial({{"pbrMetallicRoughness",
                              {{"baseColorFactor", {0.2, 0.3, 0.8, 1}},
                               {"metallicFactor", 0.0},
                               {"roughnessFactor", 0.4}}}}),
              16);
  const int cam =
      b.addCamera({{"type", "perspective"}, {"perspective", {{"yfov", 1.1}, {"znear", 0.01}}}});
  b.addNode({{"camera", cam}, {"translation", {0, 1.2, 3}}, {"rotation", {-0.17, 0, 0, 0.985}}});
  b.writeGltf(dir / "mixed.gltf");
  EXPECT_GT(test::expectTracersAgree(
                loadScene(dir / "mixed.gltf", EnvironmentDesc::constant(Rgb(0.2f, 0.2f, 0.3f))),
                options(31, 19, 6, 2)),
            0.01);
}

// Automatic picks the lanes where at least half the surface area is untextured (here a glTF
// default material, Lambertian under a specular layer; the other quad has a base colour texture).
TEST(LaneTracer, AutomaticChoiceFollowsTheUntexturedAreaShare) {
  test::TempDir dir;
  const auto twoQuads = [&](float untexturedSide, float texturedSide) {
    GltfBuilder b;
    const float u = untexturedSide, t = texturedSide;
    b.addQuad({0, 0, 0}, {u, 0, 0}, {u, u, 0}, {0, u, 0},
              b.addMaterial({{"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}}));
    const int texture = b.addTexture(1, 1, {200, 100, 50, 255});
    b.addQuad(
        {0, 0, 1}, {t, 0, 1}, {t, t, 1}, {0, t, 1},
        b.addMaterial({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", texture}}}}}}));
    const int cam =
        b.addCamera({{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.01}}}});
    b.addNode({{"camera", cam}, {"translation", {1, 1, 5}}});
    b.writeGltf(dir / "quads.gltf");
    return loadScene(dir / "quads.gltf");
  };
  const auto share = [](const Scene& scene) {
    return LaneTracer(scene, LightSet(scene), PathTracerSettings{}).untexturedAreaShare();
  };
  const auto usesLanes = [](const Scene& scene) {
    return render(scene, options(8, 8, 1, 1)).stats.lanes;
  };
  const Scene quarter = twoQuads(1, std::sqrt(3.0f));  // areas 1 and 3
  EXPECT_NEAR(share(quarter), 0.25f, 1e-5f);
  EXPECT_FALSE(usesLanes(quarter));
  const Scene threeQuarters = twoQuads(std::sqrt(3.0f), 1);
  EXPECT_NEAR(share(threeQuarters), 0.75f, 1e-5f);
  EXPECT_TRUE(usesLanes(threeQuarters));
  const Scene cornell = loadScene(test::sourceDir() / "scenes/cornell-box.gltf");
  EXPECT_EQ(share(cornell), 1.0f);
  EXPECT_TRUE(usesLanes(cornell));
  // Its checkered floor and the normal-mapped brick wall are most of these two scenes' area.
  EXPECT_FALSE(usesLanes(loadScene(test::sourceDir() / "scenes/glass-and-metal.gltf")));
  EXPECT_FALSE(usesLanes(loadScene(test::sourceDir() / "scenes/punctual-lights.gltf")));
}

}  // namespace
}  // namespace chorus::render
