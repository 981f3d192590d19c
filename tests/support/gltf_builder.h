#pragma once
// Authoring small glTF 2.0 files in tests: binary data goes into one buffer (written as a data
// URI, an external .bin, or a GLB chunk), everything else is plain JSON the test can edit.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "renderer/math/vec.h"

namespace chorus::test {

class GltfBuilder {
 public:
  GltfBuilder();

  nlohmann::json& root() { return root_; }

  // Raw data as a buffer view (4-byte aligned in the buffer); returns its index.
  int addBufferView(const void* data, size_t bytes, size_t byteStride = 0);
  // An accessor over a view.
  int addAccessor(int bufferView, int componentType, size_t count, const std::string& type,
                  bool normalized = false, size_t byteOffset = 0);
  // Float data of type SCALAR/VEC2/VEC3/VEC4 (POSITION gets min/max as the spec requires).
  int addFloats(const std::vector<float>& values, const std::string& type, bool withMinMax = false);
  int addPositions(const std::vector<render::Vec3f>& p);
  int addNormals(const std::vector<render::Vec3f>& n);
  int addUvs(const std::vector<render::Vec2f>& uv);
  // Indices as unsigned byte (5121), short (5123) or int (5125).
  int addIndices(const std::vector<uint32_t>& indices, int componentType = 5125);

  int addMaterial(const nlohmann::json& material);
  // An 8-bit RGBA PNG texture (row-major, top row first) with a sampler; returns the texture.
  int addTexture(int width, int height, const std::vector<uint8_t>& rgba,
                 const nlohmann::json& sampler = nlohmann::json::object());
  int addMesh(const std::vector<nlohmann::json>& primitives);
  static nlohmann::json primitive(int positions, int indices, int material, int normals = -1,
                                  int uvs = -1, int mode = 4);
  // A node; root nodes are listed in scene 0.
  int addNode(const nlohmann::json& node, bool isRoot = true);
  int addCamera(const nlohmann::json& camera);
  int addPunctualLight(const nlohmann::json& light);
  void requireExtension(const std::string& name);

  // Convenience: an indexed triangle mesh in a root node; returns the node.
  int addTriangleMesh(const std::vector<render::Vec3f>& positions,
                      const std::vector<uint32_t>& indices, int material,
                      const std::vector<render::Vec3f>& normals = {},
                      const std::vector<render::Vec2f>& uvs = {});
  // A UV sphere with outward normals (or inward with `inward`), in a root node.
  int addSphere(render::Vec3f center, float radius, int material, int segments = 48,
                bool inward = false);
  // A quad p0 p1 p2 p3 (counter-clockwise seen from the front), uv (0,0) at p0, (1,0) at p1.
  int addQuad(render::Vec3f p0, render::Vec3f p1, render::Vec3f p2, render::Vec3f p3, int material);

  void writeGltf(const std::filesystem::path& path, bool externalBuffer = false) const;
  void writeGlb(const std::filesystem::path& path) const;

 private:
  nlohmann::json root_;
  std::vector<uint8_t> buffer_;
};

// A minimal material: Lambertian (specularFactor 0, metallic 0) of the given colour.
nlohmann::json lambertianMaterial(float r, float g, float b);

std::string base64(const std::vector<uint8_t>& bytes);

}  // namespace chorus::test
