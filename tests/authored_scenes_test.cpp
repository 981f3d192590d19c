// The project's own scenes (scenes/*.gltf, written by scenes/generate_scenes.py) load with
// tinygltf directly and contain what scenes/README.md promises: meshes, materials, extensions,
// camera and lights, with the geometry where the scene description puts it.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>

#include "tests/support/test_support.h"

namespace {

namespace fs = std::filesystem;

tinygltf::Model load(const std::string& name) {
  const fs::path path = chorus::test::sourceDir() / "scenes" / name;
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  const bool ok = loader.LoadASCIIFromFile(&model, &error, &warning, path.string());
  EXPECT_TRUE(ok) << path << ": " << error;
  EXPECT_TRUE(error.empty()) << error;
  EXPECT_TRUE(warning.empty()) << warning;
  return model;
}

std::set<std::string> extensionsUsed(const tinygltf::Model& model) {
  return {model.extensionsUsed.begin(), model.extensionsUsed.end()};
}

const tinygltf::Material& material(const tinygltf::Model& model, const std::string& name) {
  for (const auto& m : model.materials)
    if (m.name == name) return m;
  ADD_FAILURE() << "no material named " << name;
  return model.materials.at(0);
}

const tinygltf::Node& node(const tinygltf::Model& model, const std::string& name) {
  for (const auto& n : model.nodes)
    if (n.name == name) return n;
  ADD_FAILURE() << "no node named " << name;
  return model.nodes.at(0);
}

double extensionNumber(const tinygltf::Material& m, const std::string& extension,
                       const std::string& key) {
  const auto it = m.extensions.find(extension);
  if (it == m.extensions.end()) return NAN;
  const tinygltf::Value& v = it->second.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : NAN;
}

int triangleCount(const tinygltf::Model& model, const tinygltf::Mesh& mesh) {
  int triangles = 0;
  for (const auto& p : mesh.primitives) {
    EXPECT_EQ(p.mode, TINYGLTF_MODE_TRIANGLES);
    triangles += int(model.accessors.at(size_t(p.indices)).count / 3);
  }
  return triangles;
}

// Every index refers to an existing vertex, and every buffer view lies inside its buffer.
void expectConsistentBuffers(const tinygltf::Model& model) {
  for (const auto& view : model.bufferViews)
    EXPECT_LE(view.byteOffset + view.byteLength, model.buffers.at(size_t(view.buffer)).data.size());
  for (const auto& mesh : model.meshes)
    for (const auto& p : mesh.primitives) {
      const auto& positions = model.accessors.at(size_t(p.attributes.at("POSITION")));
      const auto& indices = model.accessors.at(size_t(p.indices));
      ASSERT_EQ(indices.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
      const auto& view = model.bufferViews.at(size_t(indices.bufferView));
      const auto* data = reinterpret_cast<const uint16_t*>(
          model.buffers.at(size_t(view.buffer)).data.data() + view.byteOffset + indices.byteOffset);
      for (size_t i = 0; i < indices.count; ++i) ASSERT_LT(data[i], positions.count);
    }
}

// The camera's viewing direction: its node's rotation applied to −z.
std::array<double, 3> cameraForward(const tinygltf::Node& n) {
  const double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
  // Third column of the rotation matrix, negated.
  return {-(2 * (x * z + w * y)), -(2 * (y * z - w * x)), -(1 - 2 * (x * x + y * y))};
}

TEST(AuthoredScenes, CornellBox) {
  const tinygltf::Model model = load("cornell-box.gltf");
  EXPECT_EQ(model.meshes.size(), 3u);     // room (3 primitives), block (instanced twice), light
  EXPECT_EQ(model.materials.size(), 4u);  // white, red, green, light
  EXPECT_EQ(model.nodes.size(), 5u);      // room, two blocks, light, camera
  EXPECT_EQ(model.meshes[0].primitives.size(), 3u);
  EXPECT_EQ(extensionsUsed(model),
            (std::set<std::string>{"KHR_materials_emissive_strength", "KHR_materials_specular"}));
  EXPECT_TRUE(model.extensionsRequired.empty());
  EXPECT_EQ(model.buffers.size(), 1u);
  EXPECT_EQ(model.buffers[0].uri, "cornell-box.bin");
  expectConsistentBuffers(model);

  int triangles = 0;
  for (const auto& n : model.nodes)
    if (n.mesh >= 0) triangles += triangleCount(model, model.meshes[size_t(n.mesh)]);
  EXPECT_EQ(triangles, 10 + 12 + 12 + 2);

  // Lambertian walls: the specular layer is switched off.
  for (const char* name : {"white", "red", "green"}) {
    const auto& m = material(model, name);
    EXPECT_EQ(extensionNumber(m, "KHR_materials_specular", "specularFactor"), 0.0) << name;
    EXPECT_EQ(m.pbrMetallicRoughness.metallicFactor, 0.0) << name;
  }
  EXPECT_GT(material(model, "red").pbrMetallicRoughness.baseColorFactor[0],
            5 * material(model, "red").pbrMetallicRoughness.baseColorFactor[1]);
  EXPECT_GT(material(model, "green").pbrMetallicRoughness.baseColorFactor[1],
            2 * material(model, "green").pbrMetallicRoughness.baseColorFactor[0]);

  // One emissive quad just under the ceiling (y = 0.5488 m), facing down.
  const auto& light = material(model, "light");
  EXPECT_GT(extensionNumber(light, "KHR_materials_emissive_strength", "emissiveStrength"), 1.0);
  EXPECT_GT(light.emissiveFactor[0], 0.5);
  const auto& lightMesh = model.meshes[size_t(node(model, "light").mesh)];
  ASSERT_EQ(lightMesh.primitives.size(), 1u);
  const auto& positions =
      model.accessors[size_t(lightMesh.primitives[0].attributes.at("POSITION"))];
  EXPECT_NEAR(positions.minValues[1], 0.5483, 1e-6);
  EXPECT_NEAR(positions.maxValues[1], 0.5483, 1e-6);
  EXPECT_NEAR(positions.maxValues[0] - positions.minValues[0], 0.130, 1e-6);
  EXPECT_NEAR(positions.maxValues[2] - positions.minValues[2], 0.105, 1e-6);

  // Two blocks sharing one mesh, the tall one twice the height of the short one, rotated in
  // opposite directions.
  const auto& shortBlock = node(model, "short block");
  const auto& tallBlock = node(model, "tall block");
  EXPECT_EQ(shortBlock.mesh, tallBlock.mesh);
  EXPECT_NEAR(tallBlock.scale[1], 2 * shortBlock.scale[1], 1e-9);
  EXPECT_LT(shortBlock.rotation[1] * tallBlock.rotation[1], 0);
  // About 17° each way (quaternion y = sin(θ/2)).
  EXPECT_NEAR(std::abs(shortBlock.rotation[1]), std::sin(17.0 * M_PI / 360.0), 0.01);
  EXPECT_NEAR(std::abs(tallBlock.rotation[1]), std::sin(17.0 * M_PI / 360.0), 0.01);

  // Perspective camera with aspect 1, outside the open side, looking into the room (+z).
  ASSERT_EQ(model.cameras.size(), 1u);
  EXPECT_EQ(model.cameras[0].type, "perspective");
  EXPECT_EQ(model.cameras[0].perspective.aspectRatio, 1.0);
  EXPECT_NEAR(model.cameras[0].perspective.yfov, 2 * std::atan(12.5 / 35.0), 1e-9);
  const auto& camera = node(model, "camera");
  EXPECT_LT(camera.translation[2], 0.0);
  const auto forward = cameraForward(camera);
  EXPECT_NEAR(forward[2], 1.0, 1e-6);
  EXPECT_TRUE(model.lights.empty());
}

TEST(AuthoredScenes, GlassAndMetal) {
  const tinygltf::Model model = load("glass-and-metal.gltf");
  EXPECT_EQ(model.meshes.size(), 6u);
  EXPECT_EQ(model.materials.size(), 6u);
  EXPECT_EQ(extensionsUsed(model),
            (std::set<std::string>{"KHR_materials_emissive_strength", "KHR_materials_ior",
                                   "KHR_materials_transmission", "KHR_materials_volume"}));
  expectConsistentBuffers(model);
  // Everything is embedded: buffer and texture as data URIs.
  ASSERT_EQ(model.images.size(), 1u);
  EXPECT_EQ(model.images[0].width, 64);
  EXPECT_EQ(model.images[0].height, 64);
  EXPECT_EQ(model.buffers[0].uri.rfind("data:", 0), 0u);
  EXPECT_EQ(material(model, "checker floor").pbrMetallicRoughness.baseColorTexture.index, 0);

  const auto& glass = material(model, "glass");
  EXPECT_EQ(extensionNumber(glass, "KHR_materials_transmission", "transmissionFactor"), 1.0);
  EXPECT_EQ(extensionNumber(glass, "KHR_materials_ior", "ior"), 1.5);
  EXPECT_GT(extensionNumber(glass, "KHR_materials_volume", "thicknessFactor"), 0.0);
  EXPECT_EQ(material(model, "smooth gold").pbrMetallicRoughness.metallicFactor, 1.0);
  EXPECT_EQ(material(model, "smooth gold").pbrMetallicRoughness.roughnessFactor, 0.0);
  EXPECT_GT(material(model, "rough copper").pbrMetallicRoughness.roughnessFactor, 0.2);
  EXPECT_GE(extensionNumber(material(model, "small light"), "KHR_materials_emissive_strength",
                            "emissiveStrength"),
            100.0);

  // Three spheres on the floor (centre at the radius), sharing one set of accessors.
  std::set<int> sphereAccessors;
  for (const char* name : {"glass sphere", "smooth gold sphere", "rough copper sphere"}) {
    const auto& n = node(model, name);
    EXPECT_NEAR(n.translation[1], 0.4, 1e-9) << name;
    const auto& prim = model.meshes[size_t(n.mesh)].primitives[0];
    sphereAccessors.insert(prim.attributes.at("POSITION"));
    const auto& positions = model.accessors[size_t(prim.attributes.at("POSITION"))];
    EXPECT_NEAR(positions.maxValues[1], 0.4, 1e-6);
    EXPECT_NEAR(positions.minValues[1], -0.4, 1e-6);
  }
  EXPECT_EQ(sphereAccessors.size(), 1u);
  ASSERT_EQ(model.cameras.size(), 1u);
  EXPECT_LT(cameraForward(node(model, "camera"))[2], -0.8);  // looks towards −z
}

TEST(AuthoredScenes, PunctualLights) {
  const tinygltf::Model model = load("punctual-lights.gltf");
  EXPECT_EQ(model.meshes.size(), 4u);
  EXPECT_EQ(model.materials.size(), 4u);
  EXPECT_EQ(extensionsUsed(model), (std::set<std::string>{"KHR_lights_punctual"}));
  expectConsistentBuffers(model);
  ASSERT_EQ(model.lights.size(), 2u);
  EXPECT_EQ(model.lights[0].type, "spot");
  EXPECT_EQ(model.lights[1].type, "point");
  EXPECT_LT(model.lights[0].spot.innerConeAngle, model.lights[0].spot.outerConeAngle);
  int lightNodes = 0;
  for (const auto& n : model.nodes) lightNodes += n.extensions.count("KHR_lights_punctual");
  EXPECT_EQ(lightNodes, 2);
  // The spot light points down at the scene.
  EXPECT_LT(cameraForward(node(model, "spot light"))[1], -0.5);

  // External PNG textures: base colour and a normal map, with tangents on the floor.
  ASSERT_EQ(model.images.size(), 2u);
  for (const auto& image : model.images) {
    EXPECT_EQ(image.width, 128);
    EXPECT_TRUE(fs::exists(chorus::test::sourceDir() / "scenes" / image.uri)) << image.uri;
  }
  const auto& floor = material(model, "brick floor");
  EXPECT_GE(floor.normalTexture.index, 0);
  EXPECT_GE(floor.pbrMetallicRoughness.baseColorTexture.index, 0);
  const auto& floorPrimitive = model.meshes[size_t(node(model, "floor").mesh)].primitives[0];
  EXPECT_EQ(floorPrimitive.attributes.count("TANGENT"), 1u);
  // The normal map's mean is close to the unperturbed normal (0.5, 0.5, 1.0).
  const auto& normalImage =
      model.images[size_t(model.textures[size_t(floor.normalTexture.index)].source)];
  double meanZ = 0;
  for (size_t i = 2; i < normalImage.image.size(); i += size_t(normalImage.component))
    meanZ += normalImage.image[i] / 255.0;
  meanZ /= double(normalImage.width * normalImage.height);
  EXPECT_GT(meanZ, 0.9);
}

TEST(AuthoredScenes, StiffCaustics) {
  const tinygltf::Model model = load("stiff-caustics.gltf");
  EXPECT_EQ(extensionsUsed(model),
            (std::set<std::string>{"KHR_materials_emissive_strength", "KHR_materials_ior",
                                   "KHR_materials_specular", "KHR_materials_transmission"}));
  expectConsistentBuffers(model);
  EXPECT_EQ(model.buffers[0].uri.rfind("data:", 0), 0u);
  const auto& glass = material(model, "glass");
  EXPECT_EQ(extensionNumber(glass, "KHR_materials_transmission", "transmissionFactor"), 1.0);
  EXPECT_EQ(extensionNumber(glass, "KHR_materials_ior", "ior"), 1.5);
  // The ember is far brighter than the ceiling light and sealed inside the glass ball: same
  // centre, its radius well inside the ball's.
  const double ember = extensionNumber(material(model, "ember"), "KHR_materials_emissive_strength",
                                       "emissiveStrength");
  const double fill = extensionNumber(material(model, "ceiling light"),
                                      "KHR_materials_emissive_strength", "emissiveStrength");
  EXPECT_GT(ember, 100 * fill);
  const auto& ballNode = node(model, "glass ball");
  const auto& emberNode = node(model, "ember");
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(ballNode.translation[size_t(i)], emberNode.translation[size_t(i)]);
  auto radius = [&](const tinygltf::Node& n) {
    const auto& prim = model.meshes[size_t(n.mesh)].primitives[0];
    return model.accessors[size_t(prim.attributes.at("POSITION"))].maxValues[1];
  };
  EXPECT_LT(radius(emberNode), 0.25 * radius(ballNode));
  EXPECT_NEAR(ballNode.translation[1], radius(ballNode), 1e-6);  // resting on the floor
  ASSERT_EQ(model.cameras.size(), 1u);
  EXPECT_LT(cameraForward(node(model, "camera"))[2], -0.8);
}

TEST(AuthoredScenes, EachSceneIsSmall) {
  // Every file a scene needs stays under 200 KB in total.
  for (const char* scene :
       {"cornell-box", "glass-and-metal", "punctual-lights", "stiff-caustics"}) {
    uintmax_t bytes = 0;
    for (const auto& entry : fs::directory_iterator(chorus::test::sourceDir() / "scenes"))
      if (entry.path().filename().string().rfind(scene, 0) == 0) bytes += entry.file_size();
    EXPECT_LT(bytes, 200u * 1024u) << scene;
    EXPECT_GT(bytes, 0u) << scene;
  }
}

}  // namespace
