// glTF coverage: small files authored here exercise transforms, multi-primitive meshes, index
// types, topologies, textures, cameras, lights, materials, GLB, data URIs, and clean failures.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "common/error.h"
#include "renderer/scene/gltf_loader.h"
#include "renderer/scene/texture.h"
#include "tests/support/gltf_builder.h"
#include "tests/support/test_support.h"

namespace chorus::render {
namespace {

using nlohmann::json;
using test::GltfBuilder;
using test::TempDir;

constexpr float kTol = 1e-5f;

void expectNear(Vec3f a, Vec3f b, float tol = kTol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// One triangle (0,0,0) (1,0,0) (0,1,0) facing +z, as mesh 0 (no node).
int unitTriangleMesh(GltfBuilder& b, int material = -1) {
  const int p = b.addPositions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const int i = b.addIndices({0, 1, 2});
  return b.addMesh({GltfBuilder::primitive(p, i, material)});
}

SceneDesc writeAndLoad(const GltfBuilder& b, const TempDir& dir,
                       const std::string& name = "s.gltf") {
  b.writeGltf(dir / name);
  return loadGltf(dir / name);
}

std::string loadError(const std::filesystem::path& path) {
  try {
    loadGltf(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(GltfLoader, ComposesNodeTransformsTrsAndMatrix) {
  TempDir dir;
  GltfBuilder b;
  const int mesh = unitTriangleMesh(b);
  // child: rotate 90° about +z, scale 2; parent: matrix translating by (10, 0, 0).
  const float s = std::sqrt(0.5f);
  const int child =
      b.addNode({{"mesh", mesh}, {"rotation", {0, 0, s, s}}, {"scale", {2, 2, 2}}}, false);
  b.addNode({{"children", {child}}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1}}});
  const SceneDesc scene = writeAndLoad(b, dir);
  ASSERT_EQ(scene.meshes.size(), 1u);
  const MeshDesc& m = scene.meshes[0];
  // (1,0,0) → rotated (0,1,0) → scaled (0,2,0) → translated (10,2,0).
  expectNear(m.positions[0], {10, 0, 0});
  expectNear(m.positions[1], {10, 2, 0});
  expectNear(m.positions[2], {8, 0, 0});
  expectNear(scene.bounds.min, {8, 0, 0});
  expectNear(scene.bounds.max, {10, 2, 0});
}

TEST(GltfLoader, MirroringTransformKeepsFrontFacesCounterClockwise) {
  TempDir dir;
  GltfBuilder b;
  const int mesh = unitTriangleMesh(b);
  b.addNode({{"mesh", mesh}, {"scale", {-1, 1, 1}}});
  const SceneDesc scene = writeAndLoad(b, dir);
  const MeshDesc& m = scene.meshes[0];
  const Vec3f p0 = m.positions[m.indices[0]], p1 = m.positions[m.indices[1]],
              p2 = m.positions[m.indices[2]];
  // Mirroring x keeps the triangle facing +z; the stored winding must say so too.
  EXPECT_GT(cross(p1 - p0, p2 - p0).z, 0.0f);
}

TEST(GltfLoader, InstancesAndMultiplePrimitivesBecomeSeparateMeshes) {
  TempDir dir;
  GltfBuilder b;
  const int red = b.addMaterial(test::lambertianMaterial(1, 0, 0));
  const int green = b.addMaterial(test::lambertianMaterial(0, 1, 0));
  const int p = b.addPositions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}});
  const int i0 = b.addIndices({0, 1, 2});
  const int i1 = b.addIndices({1, 3, 2});
  const int mesh =
      b.addMesh({GltfBuilder::primitive(p, i0, red), GltfBuilder::primitive(p, i1, green)});
  b.addNode({{"mesh", mesh}});
  b.addNode({{"mesh", mesh}, {"translation", {0, 0, 5}}});
  const SceneDesc scene = writeAndLoad(b, dir);
  ASSERT_EQ(scene.meshes.size(), 4u);
  EXPECT_EQ(scene.triangleCount(), 4u);
  EXPECT_EQ(scene.materials.size(), 2u);
  EXPECT_NE(scene.meshes[0].material, scene.meshes[1].material);
  EXPECT_EQ(scene.meshes[0].material, scene.meshes[2].material);
  EXPECT_FLOAT_EQ(scene.materials[size_t(scene.meshes[1].material)].baseColor.g, 1.0f);
  EXPECT_FLOAT_EQ(scene.meshes[3].positions[0].z, 5.0f);
}

TEST(GltfLoader, ReadsEveryIndexTypeAndNonIndexedPrimitives) {
  const std::vector<uint32_t> indices = {0, 1, 2, 2, 1, 3};
  for (int type : {5121, 5123, 5125, -1}) {
    TempDir dir;
    GltfBuilder b;
    const int p = b.addPositions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}});
    int mesh;
    if (type < 0) {
      const int flat =
          b.addPositions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}});
      mesh = b.addMesh({GltfBuilder::primitive(flat, -1, -1)});
    } else {
      mesh = b.addMesh({GltfBuilder::primitive(p, b.addIndices(indices, type), -1)});
    }
    b.addNode({{"mesh", mesh}});
    const SceneDesc scene = writeAndLoad(b, dir);
    ASSERT_EQ(scene.triangleCount(), 2u) << "type " << type;
    const MeshDesc& m = scene.meshes[0];
    for (size_t k = 0; k < 6; ++k) {
      const Vec3f expected =
          std::vector<Vec3f>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}[indices[k]];
      expectNear(m.positions[m.indices[k]], expected);
    }
  }
}

TEST(GltfLoader, ConvertsStripsAndFansAndSkipsPointsAndLinesWithOneWarning) {
  TempDir dir;
  GltfBuilder b;
  const int p = b.addPositions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 2, 0}});
  const int strip = b.addIndices({0, 1, 2, 3, 4});
  const int fan = b.addIndices({0, 1, 3, 2});
  const int mesh = b.addMesh({GltfBuilder::primitive(p, strip, -1, -1, -1, 5),
                              GltfBuilder::primitive(p, fan, -1, -1, -1, 6),
                              GltfBuilder::primitive(p, -1, -1, -1, -1, 0),
                              GltfBuilder::primitive(p, -1, -1, -1, -1, 1)});
  b.addNode({{"mesh", mesh}});
  const SceneDesc scene = writeAndLoad(b, dir);
  ASSERT_EQ(scene.meshes.size(), 2u);
  // Strip of 5 vertices → 3 triangles, all facing +z (consistent winding).
  ASSERT_EQ(scene.meshes[0].triangleCount(), 3u);
  ASSERT_EQ(scene.meshes[1].triangleCount(), 2u);
  for (const MeshDesc& m : scene.meshes)
    for (size_t t = 0; t < m.indices.size(); t += 3) {
      const Vec3f a = m.positions[m.indices[t]], c = m.positions[m.indices[t + 1]],
                  d = m.positions[m.indices[t + 2]];
      EXPECT_GT(cross(c - a, d - a).z, 0.0f) << m.name << " triangle " << t / 3;
    }
  // Fan (0,1,3,2): triangles (1,3,0) and (3,2,0).
  EXPECT_EQ(scene.meshes[1].indices, (std::vector<uint32_t>{1, 3, 0, 3, 2, 0}));
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_NE(scene.warnings[0].find("2 point/line"), std::string::npos);
}

TEST(GltfLoader, NormalizedIntegerAttributes) {
  TempDir dir;
  GltfBuilder b;
  const int p = b.addPositions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const std::vector<uint16_t> uv16 = {0, 0, 65535, 0, 0, 32768};
  const int uvView = b.addBufferView(uv16.data(), uv16.size() * 2);
  const int uv = b.addAccessor(uvView, 5123, 3, "VEC2", true);
  const std::vector<int8_t> n8 = {0, 0, 127, 0, 0, 127, 0, 0, -128, 0};
  const int nView = b.addBufferView(n8.data(), 9);
  const int n = b.addAccessor(nView, 5120, 3, "VEC3", true);
  const int mesh = b.addMesh({GltfBuilder::primitive(p, -1, -1, n, uv)});
  b.addNode({{"mesh", mesh}});
  const SceneDesc scene = writeAndLoad(b, dir);
  const MeshDesc& m = scene.meshes[0];
  EXPECT_FLOAT_EQ(m.uvs[1].x, 1.0f);
  EXPECT_NEAR(m.uvs[2].y, 32768.0f / 65535.0f, 1e-6f);
  expectNear(m.normals[0], {0, 0, 1});
  expectNear(m.normals[2], {0, 0, -1});  // −128 clamps to −1
}

TEST(GltfLoader, MissingNormalsStayEmptyAndNormalMapsGetTangentsAlongU) {
  TempDir dir;
  GltfBuilder b;
  const int normalMap = b.addTexture(1, 1, {128, 128, 255, 255});
  json material = test::lambertianMaterial(1, 1, 1);
  material["normalTexture"] = {{"index", normalMap}, {"scale", 0.5}};
  const int withMap = b.addMaterial(material);
  const int plain = b.addMaterial(test::lambertianMaterial(1, 1, 1));
  // Plane in xz facing +y, u along −z, v along +x.
  b.addTriangleMesh({{0, 0, 0}, {0, 0, -1}, {1, 0, 0}}, {0, 2, 1}, withMap,
                    {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}}, {{0, 0}, {1, 0}, {0, 1}});
  b.addTriangleMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, plain);
  const SceneDesc scene = writeAndLoad(b, dir);
  ASSERT_EQ(scene.meshes.size(), 2u);
  const MeshDesc& mapped = scene.meshes[0];
  ASSERT_EQ(mapped.tangents.size(), 3u);
  for (const Tangent& t : mapped.tangents) {
    expectNear(t.xyz, {0, 0, -1});
    // bitangent = cross(n, t) · w must point along +v = +x: cross((0,1,0),(0,0,−1)) = (−1,0,0).
    EXPECT_FLOAT_EQ(t.w, -1.0f);
  }
  EXPECT_FLOAT_EQ(scene.materials[size_t(mapped.material)].normalScale, 0.5f);
  EXPECT_TRUE(scene.meshes[1].normals.empty());
  EXPECT_TRUE(scene.meshes[1].tangents.empty());
}

TEST(GltfLoader, MaterialsAndExtensions) {
  TempDir dir;
  GltfBuilder b;
  json glass = {
      {"pbrMetallicRoughness", {{"baseColorFactor", {0.9, 0.8, 0.7, 1}}, {"roughnessFactor", 0.0}}},
      {"extensions",
       {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
        {"KHR_materials_ior", {{"ior", 1.33}}},
        {"KHR_materials_volume",
         {{"thicknessFactor", 0.1},
          {"attenuationColor", {0.5, 0.6, 0.7}},
          {"attenuationDistance", 2.0}}},
        {"KHR_materials_specular",
         {{"specularFactor", 0.5}, {"specularColorFactor", {1, 0.5, 0.25}}}}}},
      {"doubleSided", true}};
  json emitter = {
      {"emissiveFactor", {1, 0.5, 0.25}},
      {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 8.0}}}}}};
  json masked = {{"alphaMode", "MASK"},
                 {"alphaCutoff", 0.25},
                 {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.5}}}}};
  b.root()["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_ior",
                                "KHR_materials_volume", "KHR_materials_specular",
                                "KHR_materials_emissive_strength"};
  for (const json& m : {glass, emitter, masked})
    b.addNode({{"mesh", unitTriangleMesh(b, b.addMaterial(m))}});
  const SceneDesc scene = writeAndLoad(b, dir);
  ASSERT_EQ(scene.materials.size(), 3u);
  EXPECT_TRUE(scene.warnings.empty());
  const MaterialDesc& g = scene.materials[0];
  EXPECT_FLOAT_EQ(g.transmission, 1.0f);
  EXPECT_FLOAT_EQ(g.ior, 1.33f);
  EXPECT_TRUE(g.hasVolume);
  EXPECT_FLOAT_EQ(g.attenuationDistance, 2.0f);
  EXPECT_FLOAT_EQ(g.attenuationColor.g, 0.6f);
  EXPECT_FLOAT_EQ(g.specular, 0.5f);
  EXPECT_FLOAT_EQ(g.specularColor.b, 0.25f);
  EXPECT_FLOAT_EQ(g.roughness, 0.0f);
  EXPECT_FLOAT_EQ(g.metallic, 1.0f);  // glTF default
  EXPECT_TRUE(g.doubleSided);
  const MaterialDesc& e = scene.materials[1];
  EXPECT_FLOAT_EQ(e.emissive.r, 8.0f);
  EXPECT_FLOAT_EQ(e.emissive.b, 2.0f);
  const MaterialDesc& m = scene.materials[2];
  EXPECT_EQ(m.alphaMode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(m.alphaCutoff, 0.25f);
  EXPECT_FLOAT_EQ(m.alpha, 0.5f);
}

TEST(GltfLoader, TexturesDecodeWithSamplerWrapModesAndSrgb) {
  TempDir dir;
  GltfBuilder b;
  // 2×1 texture: left texel sRGB 188 (≈ linear 0.5), right texel 0; alpha 255 / 51.
  const std::vector<uint8_t> rgba = {188, 188, 188, 255, 0, 0, 0, 51};
  const int repeat = b.addTexture(2, 1, rgba, {{"magFilter", 9728}});
  const int clamp = b.addTexture(2, 1, rgba, {{"wrapS", 33071}, {"magFilter", 9728}});
  const int mirror = b.addTexture(2, 1, rgba, {{"wrapS", 33648}, {"magFilter", 9728}});
  const int linear = b.addTexture(2, 1, rgba);
  for (int t : {repeat, clamp, mirror, linear}) {
    json m = {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", t}}}}}};
    b.addTriangleMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, b.addMaterial(m), {},
                      {{0, 0}, {1, 0}, {0, 1}});
  }
  const SceneDesc scene = writeAndLoad(b, dir);
  ASSERT_EQ(scene.textures.size(), 4u);
  ASSERT_EQ(scene.images.size(), 4u);
  const auto at = [&](int texture, float u, ColorEncoding enc) {
    const TextureDesc& t = scene.textures[size_t(texture)];
    return Texture(scene.images[size_t(t.image)], t).sample({u, 0.5f}, enc);
  };
  const float half = float(std::pow((188 / 255.0 + 0.055) / 1.055, 2.4));
  EXPECT_NEAR(at(0, 0.25f, ColorEncoding::Srgb)[0], half, 1e-6f);
  EXPECT_NEAR(at(0, 0.25f, ColorEncoding::Linear)[0], 188 / 255.0f, 1e-6f);
  EXPECT_NEAR(at(0, 0.75f, ColorEncoding::Srgb)[3], 0.2f, 1e-6f);  // alpha stays linear
  EXPECT_NEAR(at(0, 1.25f, ColorEncoding::Srgb)[0], half, 1e-6f);  // repeat: 1.25 → 0.25
  EXPECT_NEAR(at(1, 1.25f, ColorEncoding::Srgb)[0], 0.0f, 1e-6f);  // clamp: right texel
  EXPECT_NEAR(at(2, 1.25f, ColorEncoding::Srgb)[0], 0.0f, 1e-6f);  // mirror: 1.25 → 0.75
  EXPECT_NEAR(at(2, 1.75f, ColorEncoding::Srgb)[0], half, 1e-6f);  // mirror: 1.75 → 0.25
  // Bilinear halfway between the two texel centres, with repeat wrapping at u = 0.
  EXPECT_NEAR(at(3, 0.5f, ColorEncoding::Srgb)[0], 0.5f * half, 1e-6f);
  EXPECT_NEAR(at(3, 0.0f, ColorEncoding::Srgb)[0], 0.5f * half, 1e-6f);
}

TEST(GltfLoader, CamerasAndPunctualLightsFollowTheirNodes) {
  TempDir dir;
  GltfBuilder b;
  b.addNode({{"mesh", unitTriangleMesh(b)}});
  const int persp =
      b.addCamera({{"type", "perspective"},
                   {"perspective", {{"yfov", 0.5}, {"znear", 0.1}, {"aspectRatio", 2.0}}}});
  const int ortho =
      b.addCamera({{"type", "orthographic"},
                   {"orthographic", {{"xmag", 3}, {"ymag", 1.5}, {"znear", 0}, {"zfar", 10}}}});
  const float s = std::sqrt(0.5f);
  // Rotated 90° about +y: the camera looks down −x instead of −z.
  b.addNode({{"camera", persp}, {"translation", {5, 1, 0}}, {"rotation", {0, s, 0, s}}});
  b.addNode({{"camera", ortho}});
  const int spot =
      b.addPunctualLight({{"type", "spot"},
                          {"intensity", 20},
                          {"color", {1, 0.5, 0}},
                          {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.4}}}});
  const int sun = b.addPunctualLight({{"type", "directional"}, {"intensity", 3}});
  // Pointing down: rotate −90° about +x turns −z into −y.
  b.addNode({{"translation", {0, 4, 0}},
             {"rotation", {-s, 0, 0, s}},
             {"extensions", {{"KHR_lights_punctual", {{"light", spot}}}}}});
  b.addNode({{"extensions", {{"KHR_lights_punctual", {{"light", sun}}}}}});
  const SceneDesc scene = writeAndLoad(b, dir);
  ASSERT_EQ(scene.cameras.size(), 2u);
  const CameraDesc& c = scene.cameras[0];
  EXPECT_EQ(c.projection, ProjectionType::Perspective);
  EXPECT_FLOAT_EQ(c.yfov, 0.5f);
  EXPECT_FLOAT_EQ(c.aspectRatio, 2.0f);
  expectNear(c.position, {5, 1, 0});
  expectNear(c.forward, {-1, 0, 0});
  expectNear(c.up, {0, 1, 0});
  expectNear(c.right, {0, 0, -1});
  EXPECT_EQ(scene.cameras[1].projection, ProjectionType::Orthographic);
  EXPECT_FLOAT_EQ(scene.cameras[1].ymag, 1.5f);
  EXPECT_FLOAT_EQ(scene.cameras[1].aspectRatio, 2.0f);
  ASSERT_EQ(scene.lights.size(), 2u);
  EXPECT_EQ(scene.lights[0].type, PunctualLightType::Spot);
  expectNear(scene.lights[0].position, {0, 4, 0});
  expectNear(scene.lights[0].direction, {0, -1, 0});
  EXPECT_FLOAT_EQ(scene.lights[0].intensity, 20.0f);
  EXPECT_FLOAT_EQ(scene.lights[0].color.g, 0.5f);
  EXPECT_FLOAT_EQ(scene.lights[0].outerConeAngle, 0.4f);
  EXPECT_EQ(scene.lights[1].type, PunctualLightType::Directional);
  expectNear(scene.lights[1].direction, {0, 0, -1});
}

TEST(GltfLoader, GlbDataUriAndExternalBufferLoadTheSame) {
  TempDir dir;
  GltfBuilder b;
  const int tex = b.addTexture(1, 1, {10, 20, 30, 255});
  b.addTriangleMesh(
      {{0, 0, 0}, {2, 0, 0}, {0, 3, 0}}, {0, 1, 2},
      b.addMaterial({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", tex}}}}}}), {},
      {{0, 0}, {1, 0}, {0, 1}});
  b.writeGltf(dir / "embedded.gltf");
  b.writeGltf(dir / "external.gltf", true);
  b.writeGlb(dir / "binary.glb");
  ASSERT_TRUE(std::filesystem::exists(dir / "external.bin"));
  for (const char* name : {"embedded.gltf", "external.gltf", "binary.glb"}) {
    const SceneDesc scene = loadGltf(dir / name);
    ASSERT_EQ(scene.meshes.size(), 1u) << name;
    expectNear(scene.meshes[0].positions[2], {0, 3, 0});
    ASSERT_EQ(scene.images.size(), 1u) << name;
    EXPECT_EQ(scene.images[0].rgba, (std::vector<uint8_t>{10, 20, 30, 255})) << name;
  }
}

TEST(GltfLoader, OnlyUsedTexturesAreDecodedAndUnsupportedExtensionsWarnOnce) {
  TempDir dir;
  GltfBuilder b;
  b.addTexture(1, 1, {1, 2, 3, 4});  // referenced by no material
  // An unused image file that does not exist must not matter either.
  b.root()["images"].push_back({{"uri", "missing.png"}});
  b.root()["textures"].push_back({{"source", 1}});
  json sheen = {{"extensions", {{"KHR_materials_sheen", {{"sheenColorFactor", {1, 1, 1}}}}}}};
  b.root()["extensionsUsed"] = {"KHR_materials_sheen", "KHR_texture_transform", "KHR_xmp"};
  b.addNode({{"mesh", unitTriangleMesh(b, b.addMaterial(sheen))}});
  const SceneDesc scene = writeAndLoad(b, dir);
  EXPECT_TRUE(scene.images.empty());
  EXPECT_TRUE(scene.textures.empty());
  EXPECT_EQ(scene.warnings,
            (std::vector<std::string>{"ignoring unsupported extension KHR_materials_sheen",
                                      "ignoring unsupported extension KHR_texture_transform"}));
}

// Every failure is one chorus::Error naming the file.
class GltfLoaderErrors : public ::testing::Test {
 protected:
  void expectError(const std::filesystem::path& path, const std::string& fragment) {
    const std::string message = loadError(path);
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  TempDir dir_;
};

TEST_F(GltfLoaderErrors, MissingFile) {
  expectError(dir_ / "nope.gltf", "no such file");
}

TEST_F(GltfLoaderErrors, MalformedJson) {
  std::ofstream(dir_ / "bad.gltf") << "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [";
  expectError(dir_ / "bad.gltf", "not a readable glTF file");
}

TEST_F(GltfLoaderErrors, NotGltfAtAll) {
  std::ofstream(dir_ / "text.gltf") << "hello";
  expectError(dir_ / "text.gltf", "not a readable glTF file");
}

TEST_F(GltfLoaderErrors, MissingAndTruncatedBuffers) {
  GltfBuilder b;
  b.addNode({{"mesh", unitTriangleMesh(b)}});
  b.writeGltf(dir_ / "s.gltf", true);
  std::filesystem::resize_file(dir_ / "s.bin", 20);
  expectError(dir_ / "s.gltf", "not a readable glTF file");
  std::filesystem::remove(dir_ / "s.bin");
  expectError(dir_ / "s.gltf", "not a readable glTF file");
}

TEST_F(GltfLoaderErrors, TruncatedGlb) {
  GltfBuilder b;
  b.addNode({{"mesh", unitTriangleMesh(b)}});
  b.writeGlb(dir_ / "s.glb");
  const uintmax_t size = std::filesystem::file_size(dir_ / "s.glb");
  for (uintmax_t cut : {size - 8, size / 2, uintmax_t(10)}) {
    std::filesystem::copy_file(dir_ / "s.glb", dir_ / "cut.glb",
                               std::filesystem::copy_options::overwrite_existing);
    std::filesystem::resize_file(dir_ / "cut.glb", cut);
    expectError(dir_ / "cut.glb", "not a readable glTF file");
  }
}

TEST_F(GltfLoaderErrors, AccessorPastItsBufferView) {
  GltfBuilder b;
  const int p = b.addPositions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  b.root()["accessors"][size_t(p)]["count"] = 30;
  b.addNode({{"mesh", b.addMesh({GltfBuilder::primitive(p, -1, -1)})}});
  b.writeGltf(dir_ / "s.gltf");
  const std::string message = loadError(dir_ / "s.gltf");
  EXPECT_NE(message.find(dir_.path().string()), std::string::npos) << message;
  EXPECT_FALSE(message.empty());
}

TEST_F(GltfLoaderErrors, IndexOutOfRange) {
  GltfBuilder b;
  const int p = b.addPositions({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  b.addNode({{"mesh", b.addMesh({GltfBuilder::primitive(p, b.addIndices({0, 1, 7}), -1)})}});
  b.writeGltf(dir_ / "s.gltf");
  expectError(dir_ / "s.gltf", "vertex index 7");
}

TEST_F(GltfLoaderErrors, MissingTextureImageThatIsUsed) {
  GltfBuilder b;
  b.root()["images"].push_back({{"uri", "gone.png"}});
  b.root()["textures"].push_back({{"source", 0}});
  json m = {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}};
  b.addTriangleMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, b.addMaterial(m), {},
                    {{0, 0}, {1, 0}, {0, 1}});
  b.writeGltf(dir_ / "s.gltf");
  expectError(dir_ / "s.gltf", "gone.png");
}

TEST_F(GltfLoaderErrors, UndecodableImagesNameTheFirstInFileOrder) {
  // Images decode in parallel; the error must still be the first bad one, on every run.
  GltfBuilder b;
  for (const char* name : {"first-bad.png", "second-bad.png"}) {
    std::ofstream(dir_ / name) << "not a PNG at all";
    b.root()["images"].push_back({{"uri", name}});
    b.root()["textures"].push_back({{"source", b.root()["images"].size() - 1}});
    json m = {{"pbrMetallicRoughness",
               {{"baseColorTexture", {{"index", b.root()["textures"].size() - 1}}}}}};
    b.addTriangleMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, b.addMaterial(m), {},
                      {{0, 0}, {1, 0}, {0, 1}});
  }
  b.writeGltf(dir_ / "s.gltf");
  for (int run = 0; run < 5; ++run)
    expectError(dir_ / "s.gltf", "cannot decode image 'first-bad.png'");
}

TEST_F(GltfLoaderErrors, UnsupportedRequiredExtension) {
  GltfBuilder b;
  b.addNode({{"mesh", unitTriangleMesh(b)}});
  b.requireExtension("KHR_draco_mesh_compression");
  b.writeGltf(dir_ / "s.gltf");
  expectError(dir_ / "s.gltf", "requires extension KHR_draco_mesh_compression");
}

TEST_F(GltfLoaderErrors, NoTriangles) {
  GltfBuilder b;
  b.addNode(json::object());
  b.writeGltf(dir_ / "s.gltf");
  expectError(dir_ / "s.gltf", "no triangles");
}

}  // namespace
}  // namespace chorus::render
