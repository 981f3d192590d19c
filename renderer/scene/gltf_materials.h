#pragma once
// glTF materials, textures and images → MaterialDesc / TextureDesc / ImageDesc. Internal to the
// glTF loader. Only what the scene uses is built: a material is converted when the first
// primitive refers to it, and an image is decoded when the first used material refers to it.
#include <tiny_gltf.h>

#include <map>
#include <string>
#include <vector>

#include "renderer/scene/scene_desc.h"

namespace chorus::render::gltf {

class MaterialReader {
 public:
  // Appends to out.materials, out.textures, out.images and out.warnings.
  MaterialReader(const tinygltf::Model& model, SceneDesc& out) : model_(model), out_(out) {}

  // Index into out.materials for glTF material `gltfIndex` (−1: the glTF default material).
  int materialIndex(int gltfIndex);

 private:
  MaterialDesc convert(const tinygltf::Material& m, int gltfIndex);
  // Index into out.textures for glTF texture `gltfIndex` (−1 stays −1). `what` names the slot.
  int texture(int gltfIndex, int texCoord, const std::string& what);
  int image(int gltfIndex);
  void warnOnce(const std::string& line);

  const tinygltf::Model& model_;
  SceneDesc& out_;
  std::map<int, int> materials_, textures_, images_;
};

}  // namespace chorus::render::gltf
