#include "tests/support/gltf_builder.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

namespace chorus::test {

using nlohmann::json;
using render::Vec2f;
using render::Vec3f;

namespace {

void writeBytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

void appendU32(std::string& s, uint32_t v) {
  s.append(reinterpret_cast<const char*>(&v), 4);
}

void pngToVector(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  const auto* bytes = static_cast<const uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

}  // namespace

std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t b0 = bytes[i];
    const uint32_t b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0;
    const uint32_t b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0;
    const uint32_t triple = (b0 << 16) | (b1 << 8) | b2;
    out += kAlphabet[(triple >> 18) & 63];
    out += kAlphabet[(triple >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(triple >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[triple & 63] : '=';
  }
  return out;
}

json lambertianMaterial(float r, float g, float b) {
  return {{"pbrMetallicRoughness", {{"baseColorFactor", {r, g, b, 1.0}}, {"metallicFactor", 0.0}}},
          {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0.0}}}}}};
}

GltfBuilder::GltfBuilder() {
  root_ = {{"asset", {{"version", "2.0"}}},
           {"scene", 0},
           {"scenes", json::array({json{{"nodes", json::array()}}})},
           {"nodes", json::array()}};
}

int GltfBuilder::addBufferView(const void* data, size_t bytes, size_t byteStride) {
  while (buffer_.size() % 4 != 0) buffer_.push_back(0);
  const size_t offset = buffer_.size();
  const auto* p = static_cast<const uint8_t*>(data);
  buffer_.insert(buffer_.end(), p, p + bytes);
  json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
  if (byteStride) view["byteStride"] = byteStride;
  root_["bufferViews"].push_back(view);
  return int(root_["bufferViews"].size()) - 1;
}

int GltfBuilder::addAccessor(int bufferView, int componentType, size_t count,
                             const std::string& type, bool normalized, size_t byteOffset) {
  json a = {{"bufferView", bufferView},
            {"componentType", componentType},
            {"count", count},
            {"type", type}};
  if (normalized) a["normalized"] = true;
  if (byteOffset) a["byteOffset"] = byteOffset;
  root_["accessors"].push_back(a);
  return int(root_["accessors"].size()) - 1;
}

int GltfBuilder::addFloats(const std::vector<float>& values, const std::string& type,
                           bool withMinMax) {
  const size_t components = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
  const int view = addBufferView(values.data(), values.size() * sizeof(float));
  const int accessor = addAccessor(view, 5126, values.size() / components, type);
  if (withMinMax && !values.empty()) {
    std::vector<float> lo(components, INFINITY), hi(components, -INFINITY);
    for (size_t i = 0; i < values.size(); ++i) {
      lo[i % components] = std::min(lo[i % components], values[i]);
      hi[i % components] = std::max(hi[i % components], values[i]);
    }
    root_["accessors"][size_t(accessor)]["min"] = lo;
    root_["accessors"][size_t(accessor)]["max"] = hi;
  }
  return accessor;
}

int GltfBuilder::addPositions(const std::vector<Vec3f>& p) {
  std::vector<float> v;
  for (const Vec3f& x : p) v.insert(v.end(), {x.x, x.y, x.z});
  return addFloats(v, "VEC3", true);
}

int GltfBuilder::addNormals(const std::vector<Vec3f>& n) {
  std::vector<float> v;
  for (const Vec3f& x : n) v.insert(v.end(), {x.x, x.y, x.z});
  return addFloats(v, "VEC3");
}

int GltfBuilder::addUvs(const std::vector<Vec2f>& uv) {
  std::vector<float> v;
  for (const Vec2f& x : uv) v.insert(v.end(), {x.x, x.y});
  return addFloats(v, "VEC2");
}

int GltfBuilder::addIndices(const std::vector<uint32_t>& indices, int componentType) {
  std::vector<uint8_t> bytes;
  const size_t size = componentType == 5121 ? 1 : componentType == 5123 ? 2 : 4;
  for (uint32_t i : indices) {
    const auto* p = reinterpret_cast<const uint8_t*>(&i);
    bytes.insert(bytes.end(), p, p + size);
  }
  const int view = addBufferView(bytes.data(), bytes.size());
  return addAccessor(view, componentType, indices.size(), "SCALAR");
}

int GltfBuilder::addMaterial(const json& material) {
  root_["materials"].push_back(material);
  return int(root_["materials"].size()) - 1;
}

int GltfBuilder::addTexture(int width, int height, const std::vector<uint8_t>& rgba,
                            const json& sampler) {
  std::vector<uint8_t> png;
  stbi_write_png_to_func(pngToVector, &png, width, height, 4, rgba.data(), width * 4);
  const int view = addBufferView(png.data(), png.size());
  root_["images"].push_back({{"bufferView", view}, {"mimeType", "image/png"}});
  root_["samplers"].push_back(sampler);
  root_["textures"].push_back(
      {{"source", root_["images"].size() - 1}, {"sampler", root_["samplers"].size() - 1}});
  return int(root_["textures"].size()) - 1;
}

int GltfBuilder::addMesh(const std::vector<json>& primitives) {
  root_["meshes"].push_back({{"primitives", primitives}});
  return int(root_["meshes"].size()) - 1;
}

json GltfBuilder::primitive(int positions, int indices, int material, int normals, int uvs,
                            int mode) {
  json p = {{"attributes", {{"POSITION", positions}}}};
  if (normals >= 0) p["attributes"]["NORMAL"] = normals;
  if (uvs >= 0) p["attributes"]["TEXCOORD_0"] = uvs;
  if (indices >= 0) p["indices"] = indices;
  if (material >= 0) p["material"] = material;
  if (mode != 4) p["mode"] = mode;
  return p;
}

int GltfBuilder::addNode(const json& node, bool isRoot) {
  root_["nodes"].push_back(node);
  const int index = int(root_["nodes"].size()) - 1;
  if (isRoot) root_["scenes"][0]["nodes"].push_back(index);
  return index;
}

int GltfBuilder::addCamera(const json& camera) {
  root_["cameras"].push_back(camera);
  return int(root_["cameras"].size()) - 1;
}

int GltfBuilder::addPunctualLight(const json& light) {
  json& lights = root_["extensions"]["KHR_lights_punctual"]["lights"];
  lights.push_back(light);
  json& used = root_["extensionsUsed"];
  if (std::find(used.begin(), used.end(), "KHR_lights_punctual") == used.end())
    used.push_back("KHR_lights_punctual");
  return int(lights.size()) - 1;
}

void GltfBuilder::requireExtension(const std::string& name) {
  root_["extensionsUsed"].push_back(name);
  root_["extensionsRequired"].push_back(name);
}

int GltfBuilder::addTriangleMesh(const std::vector<Vec3f>& positions,
                                 const std::vector<uint32_t>& indices, int material,
                                 const std::vector<Vec3f>& normals, const std::vector<Vec2f>& uvs) {
  const int p = addPositions(positions);
  const int i = addIndices(indices);
  const int n = normals.empty() ? -1 : addNormals(normals);
  const int t = uvs.empty() ? -1 : addUvs(uvs);
  const int mesh = addMesh({primitive(p, i, material, n, t)});
  return addNode({{"mesh", mesh}});
}

int GltfBuilder::addSphere(Vec3f center, float radius, int material, int segments, bool inward) {
  std::vector<Vec3f> positions, normals;
  std::vector<uint32_t> indices;
  const int rings = segments / 2;
  for (int r = 0; r <= rings; ++r) {
    const float theta = float(r) / float(rings) * render::kPi;
    for (int s = 0; s <= segments; ++s) {
      const float phi = float(s) / float(segments) * 2.0f * render::kPi;
      const Vec3f n{std::sin(theta) * std::cos(phi), std::cos(theta),
                    -std::sin(theta) * std::sin(phi)};
      positions.push_back(center + n * radius);
      normals.push_back(inward ? -n : n);
    }
  }
  const uint32_t stride = uint32_t(segments + 1);
  for (uint32_t r = 0; r < uint32_t(rings); ++r) {
    for (uint32_t s = 0; s < uint32_t(segments); ++s) {
      const uint32_t a = r * stride + s, b = a + stride, c = b + 1, d = a + 1;
      if (inward)
        indices.insert(indices.end(), {a, d, b, d, c, b});
      else
        indices.insert(indices.end(), {a, b, d, d, b, c});
    }
  }
  return addTriangleMesh(positions, indices, material, normals);
}

int GltfBuilder::addQuad(Vec3f p0, Vec3f p1, Vec3f p2, Vec3f p3, int material) {
  const Vec3f n = render::normalize(render::cross(p1 - p0, p3 - p0));
  return addTriangleMesh({p0, p1, p2, p3}, {0, 1, 2, 0, 2, 3}, material, {n, n, n, n},
                         {{0, 0}, {1, 0}, {1, 1}, {0, 1}});
}

void GltfBuilder::writeGltf(const std::filesystem::path& path, bool externalBuffer) const {
  json root = root_;
  if (!buffer_.empty()) {
    json buffer = {{"byteLength", buffer_.size()}};
    if (externalBuffer) {
      const std::string binName = path.stem().string() + ".bin";
      buffer["uri"] = binName;
      writeBytes(path.parent_path() / binName, std::string(buffer_.begin(), buffer_.end()));
    } else {
      buffer["uri"] = "data:application/octet-stream;base64," + base64(buffer_);
    }
    root["buffers"] = json::array({buffer});
  }
  writeBytes(path, root.dump(1));
}

void GltfBuilder::writeGlb(const std::filesystem::path& path) const {
  json root = root_;
  std::vector<uint8_t> bin = buffer_;
  while (bin.size() % 4 != 0) bin.push_back(0);
  if (!bin.empty()) root["buffers"] = json::array({json{{"byteLength", buffer_.size()}}});
  std::string text = root.dump();
  while (text.size() % 4 != 0) text.push_back(' ');
  std::string out = "glTF";
  appendU32(out, 2);
  appendU32(out, uint32_t(12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size())));
  appendU32(out, uint32_t(text.size()));
  appendU32(out, 0x4E4F534A);  // "JSON"
  out += text;
  if (!bin.empty()) {
    appendU32(out, uint32_t(bin.size()));
    appendU32(out, 0x004E4942);  // "BIN\0"
    out.append(reinterpret_cast<const char*>(bin.data()), bin.size());
  }
  writeBytes(path, out);
}

}  // namespace chorus::test
