#pragma once
// glTF materials, textures and images → MaterialDesc / TextureDesc / ImageDesc. Internal to the
// glTF loader. Only what the scene uses is built: a material is converted when the first
// primitive refers to it, and only the images used materials refer to are decoded (all at once, in
// parallel, by decodeImages()).
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
  // Decodes the images the converted materials use, in parallel (a textured model's PNGs were
  // most of its load time); until then out.images holds only their names. Call once, last.
  void decodeImages();

 private:
  MaterialDesc convert(const tinygltf::Material& m, int gltfIndex);
  // Index into out.textures for glTF texture `gltfIndex` (−1 stays −1). `what` names the slot.
  int texture(int gltfIndex, int texCoord, const std::string& what);
  int image(int gltfIndex);
  void warnOnce(const std::string& line);

  const tinygltf::Model& model_;
  SceneDesc& out_;
  std::map<int, int> materials_, textures_, images_;
  std::vector<const tinygltf::Image*> pendingImages_;  // the source of each out.images entry
};

}  // namespace chorus::render::gltf
